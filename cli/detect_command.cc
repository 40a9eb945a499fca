// hadynet detect: contact detection over logs with a calibrated model (seed
// paper III-D): per step the N_detect-step prediction error, its Mahalanobis
// distance d and the contact flag d > C_detect; a summary per log, the traces
// as CSV and a PNG with one panel per log.
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/gnuplot.h"
#include "cli/options.h"
#include "cli/pb_adapt_common.h"
#include "cli/trainer_inputs.h"
#include "trainer/detection.h"
#include "trainer/model_file.h"

namespace hadynet::cli {

namespace {

struct Trace {
  std::string name;
  Eigen::VectorXd d;  // element j: step t = j + 1 + N_detect
};

std::string trace_plot(const std::vector<Trace>& traces, int first_step, double threshold,
                       const std::string& title, const std::string& png) {
  std::string s;
  for (std::size_t i = 0; i < traces.size(); ++i) {
    s += "$d" + std::to_string(i) + " << EOD\n";
    char buf[48];
    for (Eigen::Index j = 0; j < traces[i].d.size(); ++j) {
      std::snprintf(buf, sizeof buf, "%ld %.6g\n", static_cast<long>(j + first_step), traces[i].d(j));
      s += buf;
    }
    s += "EOD\n";
  }
  const std::size_t rows = (traces.size() + 1) / 2;
  s += "set terminal pngcairo size 1400," + std::to_string(200 * rows + 80) + " font 'sans,9' noenhanced\n";
  s += "set output " + gnuplot_quote(png) + "\n";
  s += "set multiplot layout " + std::to_string(rows) + ",2 title " + gnuplot_quote(title) + "\n";
  s += "set grid\nset logscale y\nset ylabel 'd'\nset xlabel 'step'\n";
  char thr[64];
  std::snprintf(thr, sizeof thr, "%.6g", threshold);
  for (std::size_t i = 0; i < traces.size(); ++i) {
    s += "set title " + gnuplot_quote(traces[i].name) + "\n";
    s += "plot $d" + std::to_string(i) + " using 1:2 with lines lw 1 title 'd', " + thr +
         " with lines dt 2 lw 2 lc rgb 'red' title 'C_detect'\n";
  }
  s += "unset multiplot\n";
  return run_gnuplot(s, png);
}

}  // namespace

int run_detect(int argc, char** argv) {
  Options opt("detect",
              "Runs contact detection over logs with a model calibrated by calibrate-detect: d per step and\n"
              "the contact flag d > C_detect. Prints per log the share of steps flagged, the median and\n"
              "maximum d; --csv writes the traces, --plot draws them. --pb swaps the calibrated PB (e.g. a\n"
              "stale trained PB) to see what an out-of-date PB does to detection.",
              "MODEL LOG|DIR... [options]");
  opt.value("pb", "PB", "calibrated, zero, a state of the model, or comma-separated values", "calibrated");
  opt.value("csv", "FILE", "write log,step,d,contact rows");
  opt.value("plot", "PNG", "draw d against C_detect, one panel per log");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (opt.positional().size() < 2) {
    std::fprintf(stderr, "hadynet detect: give MODEL and logs (see --help)\n");
    return 2;
  }
  try {
    const trainer::HadynetModel model = trainer::load_model(opt.positional().front());
    if (!model.detection) {
      throw std::runtime_error(opt.positional().front() +
                               ": model has no detection calibration (run hadynet calibrate-detect)");
    }
    const trainer::DetectionCalibration& cal = *model.detection;
    const Eigen::VectorXf pb =
        opt.get("pb") == "calibrated" ? cal.pb.cast<float>() : parse_pb(model, opt.get("pb"));
    const std::vector<std::string> log_args(opt.positional().begin() + 1, opt.positional().end());
    std::FILE* csv = nullptr;
    if (opt.has("csv")) {
      csv = std::fopen(opt.get("csv").c_str(), "w");
      if (csv == nullptr) throw std::runtime_error(opt.get("csv") + ": cannot write");
      std::fprintf(csv, "log,step,d,contact\n");
    }
    std::vector<Trace> traces;
    std::printf("C_detect %.3f, N_detect %d, PB %s\n", cal.threshold, cal.steps, opt.get("pb").c_str());
    std::printf("%-40s %-11s %7s %9s %9s %9s\n", "log", "object", "steps", "flagged", "median d", "max d");
    for (const auto& seq : read_sequences(log_args, model)) {
      const Eigen::VectorXd d = trainer::detection_distances(model, cal, seq, pb);
      std::vector<double> v(d.data(), d.data() + d.size());
      const long flagged = (d.array() > cal.threshold).count();
      const std::string name = std::filesystem::path(seq.file).filename().string();
      std::printf("%-40s %-11s %7ld %8.1f%% %9.2f %9.2f\n", name.c_str(), seq.object.c_str(),
                  static_cast<long>(d.size()), d.size() ? 100.0 * static_cast<double>(flagged) / static_cast<double>(d.size()) : 0.0,
                  trainer::quantile(v, 0.5), trainer::quantile(v, 1.0));
      if (csv != nullptr) {
        for (Eigen::Index j = 0; j < d.size(); ++j)
          std::fprintf(csv, "%s,%ld,%.6g,%d\n", name.c_str(), static_cast<long>(j + 1 + cal.steps), d(j),
                       d(j) > cal.threshold ? 1 : 0);
      }
      traces.push_back({name, d});
    }
    if (csv != nullptr) {
      std::fclose(csv);
      std::fprintf(stderr, "wrote %s\n", opt.get("csv").c_str());
    }
    if (opt.has("plot")) {
      const std::string err = trace_plot(traces, 1 + cal.steps, cal.threshold,
                                         "contact detection: d per step (PB " + opt.get("pb") + ")",
                                         opt.get("plot"));
      if (!err.empty()) throw std::runtime_error(err);
      std::fprintf(stderr, "wrote %s\n", opt.get("plot").c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet detect: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
