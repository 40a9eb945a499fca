// hadynet adapt: PB-only adaptation with frozen weights (docs/method.md, "PB adaptation").
// Offline: one PB per dynamics state of the given logs, full batch,
// MomentumSGD, --epochs epochs. --online: the logs are streamed step by step;
// the PB is updated once 100 windows exist, on the newest 200, 3 epochs per
// step, and its trajectory is printed (CSV) and drawn on the PB map.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/options.h"
#include "cli/pb_adapt_common.h"
#include "cli/pb_map_plot.h"
#include "cli/threads_option.h"
#include "cli/trainer_inputs.h"
#include "trainer/model_file.h"
#include "trainer/pb_adaptation.h"
#include "trainer/recognition.h"

namespace hadynet::cli {

namespace {

int run_online(const trainer::HadynetModel& model, const std::vector<trainer::LogSequence>& logs,
               const Eigen::VectorXf& start, const trainer::OnlinePbAdapter::Options& options,
               const std::string& csv_path, const std::string& png) {
  std::FILE* csv = stdout;
  if (!csv_path.empty()) {
    csv = std::fopen(csv_path.c_str(), "w");
    if (csv == nullptr) throw std::runtime_error(csv_path + ": cannot write");
  }
  std::fprintf(csv, "log,t_step,windows,loss");
  for (int i = 0; i < model.params.dims.pb; ++i) std::fprintf(csv, ",p%d", i);
  std::fprintf(csv, ",nearest,distance\n");
  std::vector<Eigen::VectorXf> trajectory;
  std::vector<MarkedPb> finals;
  trainer::OnlinePbAdapter adapter(model, start, options);
  for (const auto& seq : logs) {
    adapter.begin_segment();
    for (int t = 0; t < seq.steps(); ++t) {
      if (!adapter.push(seq.y.col(t), seq.u.col(t))) continue;
      std::fprintf(csv, "%s,%d,%d,%.6g", seq.file.c_str(), t, adapter.windows(), adapter.last_loss());
      for (Eigen::Index i = 0; i < adapter.pb().size(); ++i)
        std::fprintf(csv, ",%.6g", static_cast<double>(adapter.pb()(i)));
      const trainer::NearestPb nearest = trainer::nearest_pb(model, adapter.pb());
      std::fprintf(csv, ",%s,%.6g\n",
                   nearest.state < 0 ? "" : model.states[static_cast<std::size_t>(nearest.state)].name.c_str(),
                   nearest.distance);
      trajectory.push_back(adapter.pb());
    }
    finals.push_back({(seq.object.empty() ? seq.state : seq.object) + " (end of log)", adapter.pb()});
  }
  if (csv != stdout) {
    std::fclose(csv);
    std::fprintf(stderr, "wrote %s\n", csv_path.c_str());
  }
  if (!png.empty()) {
    const std::string err =
        plot_pb_map(model, finals, trajectory, "online PB trajectory on the trained PB map", png);
    if (!err.empty()) throw std::runtime_error(err);
    std::fprintf(stderr, "wrote %s\n", png.c_str());
  }
  return 0;
}

}  // namespace

int run_adapt(int argc, char** argv) {
  Options opt("adapt",
              "Fits the PB alone to logs of a new dynamics state, the network weights frozen (MomentumSGD,\n"
              "full batch, BN in eval mode). Offline: one PB per state of the logs (metadata 'state'), with\n"
              "the loss before and after. --online: the logs are streamed one after the other, step by step as on\n"
              "the robot (one window buffer, PB and momentum throughout; windows never span two logs); the PB\n"
              "trajectory is printed as CSV and, with --plot, drawn on the map of the trained PBs.",
              "MODEL LOG|DIR... [options]");
  add_adapt_options(opt);
  add_threads_option(opt, "1");
  opt.flag("online", "stream the logs step by step (paper: start at 100 windows, newest 200, 3 epochs)");
  opt.value("start-windows", "N", "online: windows before the first update", "100");
  opt.value("max-windows", "N", "online: newest windows kept", "200");
  opt.value("online-epochs", "N", "online: epochs per update", "3");
  opt.value("csv", "FILE", "online: write the PB trajectory here instead of stdout (per update: log, t_step, windows,\n"
            "loss, p0.., the nearest trained state and its distance)");
  opt.value("plot", "PNG", "online: draw the trajectory on the PB map");
  opt.value("json", "FILE", "offline: write the results as JSON");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (!apply_threads_option(opt, "adapt")) return 2;
  if (opt.positional().size() < 2) {
    std::fprintf(stderr, "hadynet adapt: give MODEL and logs (see --help)\n");
    return 2;
  }
  const auto adapt = adapt_options(opt);
  const auto start_windows = opt.get_int("start-windows", 1, 1000000);
  const auto max_windows = opt.get_int("max-windows", 1, 1000000);
  const auto online_epochs = opt.get_int("online-epochs", 1, 1000000);
  if (!adapt || !start_windows || !max_windows || !online_epochs) return 2;
  try {
    const trainer::HadynetModel model = trainer::load_model(opt.positional().front());
    const std::vector<std::string> log_args(opt.positional().begin() + 1, opt.positional().end());
    std::vector<trainer::LogSequence> logs = read_sequences(log_args, model);
    const std::vector<Eigen::VectorXf> starts = parse_start_pbs(model, opt.get("start"));
    if (opt.has("online")) {
      if (starts.size() != 1) throw std::runtime_error("--online adapts from one start PB (not 'objects')");
      const Eigen::VectorXf& start = starts.front();
      trainer::OnlinePbAdapter::Options online;
      online.start_windows = static_cast<int>(*start_windows);
      online.max_windows = static_cast<int>(*max_windows);
      online.adapt = *adapt;
      online.adapt.epochs = static_cast<int>(*online_epochs);
      return run_online(model, logs, start, online, opt.get("csv"), opt.get("plot"));
    }
    const std::vector<AdaptedState> results =
        adapt_each_state(model, group_by_state(std::move(logs)), starts, *adapt);
    std::printf("%-22s %-11s %7s %11s %11s %7s  PB\n", "state", "object", "windows", "loss before",
                "loss after", "drop");
    for (const auto& r : results) {
      std::printf("%-22s %-11s %7d %11.5f %11.5f %6.1f%%  %s\n", r.state.c_str(), r.object.c_str(),
                  r.windows, r.result.loss.front(), r.result.loss.back(), r.drop_percent(),
                  format_pb(r.result.pb).c_str());
      if (r.result.halvings > 0)
        std::printf("  (the step was halved %d times: --lr %g is too large for these data)\n", r.result.halvings,
                    adapt->lr);
    }
    if (opt.has("json")) {
      write_adapt_json(opt.get("json"), results);
      std::fprintf(stderr, "wrote %s\n", opt.get("json").c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet adapt: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
