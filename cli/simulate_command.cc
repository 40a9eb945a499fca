// hadynet simulate: contact simulation (seed paper III-E): HADYNET run forward
// from the state x_t of a log with that log's commands and any PB, written as
// a predicted log (docs/log-format.md) and drawn against the measured one.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/gnuplot.h"
#include "cli/options.h"
#include "cli/pb_adapt_common.h"
#include "cli/trainer_inputs.h"
#include "datalog/log_reader.h"
#include "datalog/log_writer.h"
#include "trainer/model_file.h"
#include "trainer/prediction.h"

namespace hadynet::cli {

namespace {

// Panels per observed group: measured (solid) and predicted (dashed).
std::string comparison_plot(const trainer::FeatureLayout& layout, const Eigen::VectorXd& time,
                            const Eigen::MatrixXd& measured, const Eigen::MatrixXd& predicted,
                            const std::string& title, const std::string& png) {
  std::vector<std::pair<std::string, std::vector<int>>> groups;
  for (std::size_t i = 0; i < layout.y_names.size(); ++i) {
    const std::string g = trainer::channel_group(layout.y_names[i]);
    if (groups.empty() || groups.back().first != g) groups.push_back({g, {}});
    groups.back().second.push_back(static_cast<int>(i));
  }
  std::string s = "$d << EOD\n";
  char buf[48];
  for (Eigen::Index k = 0; k < time.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.6g", time(k));
    s += buf;
    for (Eigen::Index i = 0; i < measured.rows(); ++i) {
      std::snprintf(buf, sizeof buf, " %.6g %.6g", measured(i, k), predicted(i, k));
      s += buf;
    }
    s += "\n";
  }
  s += "EOD\n";
  s += "set terminal pngcairo size 1200," + std::to_string(240 * groups.size() + 60) +
       " font 'sans,9' noenhanced\n";
  s += "set output " + gnuplot_quote(png) + "\n";
  s += "set multiplot layout " + std::to_string(groups.size()) + ",1 title " +
       gnuplot_quote(title + "   (solid: measured, dashed: HADYNET)") + "\n";
  s += "set key outside right top spacing 0.8\nset grid\nset lmargin 10\nset rmargin 14\n";
  for (std::size_t p = 0; p < groups.size(); ++p) {
    s += "set ylabel " + gnuplot_quote(groups[p].first) + "\n";
    s += p + 1 == groups.size() ? "set xlabel 't [s]'\n" : "unset xlabel\n";
    s += "plot ";
    int colour = 1;
    for (int i : groups[p].second) {
      const std::string m = std::to_string(2 + 2 * i), e = std::to_string(3 + 2 * i);
      if (colour > 1) s += ", ";
      s += "$d using 1:" + m + " with lines lw 1 lc " + std::to_string(colour) + " title " +
           gnuplot_quote(layout.y_names[static_cast<std::size_t>(i)]) + ", $d using 1:" + e +
           " with lines lw 1.5 dt 2 lc " + std::to_string(colour) + " notitle";
      ++colour;
    }
    s += "\n";
  }
  s += "unset multiplot\n";
  return run_gnuplot(s, png);
}

}  // namespace

int run_simulate(int argc, char** argv) {
  Options opt("simulate",
              "Contact simulation: runs HADYNET forward from the state x_t of a log (t = --from) with the\n"
              "log's commands u_t, u_t+1, ... under a PB of your choice, writes the predicted observations as a\n"
              "log, prints the RMS error per channel group against the measured log, and with --plot draws\n"
              "both. Swap the PB to ask 'what would these commands do holding another object'.",
              "MODEL --log LOG --out PRED.csv [options]");
  add_adapt_options(opt);
  opt.value("log", "LOG", "log giving the start state and the commands (and the measurement to compare)");
  opt.value("out", "CSV", "predicted log to write");
  opt.value("from", "T", "start step t (x_t needs t >= 1)", "1");
  opt.value("horizon", "N", "steps to predict (0: to the end of the log)", "0");
  opt.value("pb", "PB", "zero, a state of the model, comma-separated values, or adapt (fit to --log)",
            "adapt");
  opt.value("plot", "PNG", "draw measured and predicted channels");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (opt.positional().size() != 1 || !opt.has("log") || !opt.has("out")) {
    std::fprintf(stderr, "hadynet simulate: give MODEL, --log and --out (see --help)\n");
    return 2;
  }
  const auto from = opt.get_int("from", 1, 1 << 30);
  const auto steps = opt.get_int("horizon", 0, 1 << 30);
  const auto adapt = adapt_options(opt);
  if (!from || !steps || !adapt) return 2;
  try {
    const trainer::HadynetModel model = trainer::load_model(opt.positional().front());
    const std::string log_path = opt.get("log");
    const datalog::LogTable table = datalog::read_log(log_path);
    const trainer::LogSequence seq = trainer::in_model_frame(model.sensor, model.layout, table, log_path).sequence;
    const int t0 = static_cast<int>(*from);
    const int n = *steps == 0 ? seq.steps() - 1 - t0 : static_cast<int>(*steps);
    if (t0 >= seq.steps() - 1 || n < 1 || t0 + n > seq.steps() - 1) {
      throw std::runtime_error(log_path + " has " + std::to_string(seq.steps()) +
                               " rows: cannot predict " + std::to_string(n) + " steps from t = " +
                               std::to_string(t0));
    }
    Eigen::VectorXf pb;
    if (opt.get("pb") == "adapt") {
      const trainer::AdaptResult r =
          adapt_each_state(model, {{seq.state, seq.object, {seq}}}, parse_start_pbs(model, opt.get("start")), *adapt)
              .front()
              .result;
      pb = r.pb;
      std::printf("PB adapted to %s: loss %.5g -> %.5g in %d epochs%s\n", log_path.c_str(), r.loss.front(),
                  r.loss.back(), adapt->epochs,
                  r.halvings > 0 ? (" (step halved " + std::to_string(r.halvings) + " times)").c_str() : "");
    } else {
      pb = parse_pb(model, opt.get("pb"));
    }
    const Eigen::MatrixXd predicted =
        trainer::simulate(model, trainer::initial_state(model.layout, seq, t0), seq.u.middleCols(t0, n), pb);
    if (!predicted.allFinite()) {
      throw std::runtime_error(opt.positional().front() + ": the simulation is not finite (float32 overflow in the "
                               "network on " + log_path + "); nothing written");
    }
    const Eigen::MatrixXd measured = seq.y.middleCols(t0 + 1, n);

    // The predicted log: t, y channels, the commands that produced them.
    const auto t_col = table.column_index("t");
    const double dt = datalog::log_dt_s(table, log_path);
    datalog::LogTable out;
    out.metadata.set("format", "hadynet-log");
    out.metadata.set("format_version", "1");
    out.metadata.set("dt_s", table.metadata.get("dt_s").value_or("0.2"));
    out.metadata.set("state", "simulated");
    if (auto object = table.metadata.get("object")) out.metadata.set("object", *object);
    if (auto units = table.metadata.get("units")) out.metadata.set("units", *units);
    out.metadata.set("source", "hadynet simulate: " + opt.positional().front() + " from " + log_path +
                                   " t=" + std::to_string(t0) + ", PB " + format_pb(pb));
    out.columns.push_back("t");
    for (const auto& name : model.layout.y_names) out.columns.push_back(name);
    for (const auto& name : model.layout.u_names) out.columns.push_back(name);
    Eigen::VectorXd time(n);
    for (int k = 0; k < n; ++k) {
      const int t = t0 + 1 + k;
      time(k) = t_col ? table.at(static_cast<std::size_t>(t), *t_col) : t * dt;
      std::vector<double> row{time(k)};
      for (Eigen::Index i = 0; i < predicted.rows(); ++i) row.push_back(predicted(i, k));
      for (Eigen::Index i = 0; i < seq.u.rows(); ++i)
        row.push_back(seq.u(i, t));
      out.append_row(row);
    }
    datalog::write_log(opt.get("out"), out);
    std::printf("predicted %d steps from t = %d with PB %s; RMS error per group (physical units):\n", n,
                t0, format_pb(pb).c_str());
    for (std::size_t i = 0; i < model.layout.y_names.size();) {
      const std::string g = trainer::channel_group(model.layout.y_names[i]);
      double sq = 0.0;
      long count = 0;
      for (; i < model.layout.y_names.size() && trainer::channel_group(model.layout.y_names[i]) == g; ++i) {
        sq += (predicted.row(static_cast<Eigen::Index>(i)) - measured.row(static_cast<Eigen::Index>(i))).squaredNorm();
        count += n;
      }
      std::printf("  %-4s %.4g\n", g.c_str(), std::sqrt(sq / static_cast<double>(count)));
    }
    std::printf("wrote %s\n", opt.get("out").c_str());
    if (opt.has("plot")) {
      const std::string err = comparison_plot(model.layout, time, measured, predicted,
                                              std::filesystem::path(log_path).filename().string(),
                                              opt.get("plot"));
      if (!err.empty()) throw std::runtime_error(err);
      std::printf("wrote %s\n", opt.get("plot").c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet simulate: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
