// hadynet train: learns HADYNET and the PB table from logs (docs/method.md,
// "Network" and "Training"). Progress with loss and ETA on stderr, a checkpoint after
// every epoch (atomic; --resume continues exactly), the model file at the end,
// and the loss history as CSV and PNG next to it.
#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/gnuplot.h"
#include "cli/options.h"
#include "cli/trainer_inputs.h"
#include "datalog/log_reader.h"
#include "hadynet_build_info.h"
#include "trainer/checkpoint.h"
#include "trainer/deploy_prep.h"
#include "trainer/held_out_logs.h"
#include "trainer/model_file.h"
#include "trainer/training.h"
#include "trainer/training_record.h"
#include "trainer/work_pool.h"

namespace hadynet::cli {
namespace fs = std::filesystem;

namespace {

std::string duration(double seconds) {
  char buf[32];
  const long s = std::lround(seconds);
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", s / 3600, (s / 60) % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%ldm%02lds", s / 60, s % 60);
  }
  return buf;
}

void write_history(const std::string& csv, const std::vector<trainer::EpochStats>& history) {
  std::ofstream out(csv);
  out << "epoch,train_loss,held_out_loss,seconds\n";
  for (const auto& e : history) {
    out << e.epoch << ',' << e.train_loss << ',';
    if (std::isfinite(e.held_out_loss)) out << e.held_out_loss;
    out << ',' << e.seconds << '\n';
  }
}

std::string history_plot(const std::string& csv, const std::string& png, const std::string& title) {
  std::string s = "set terminal pngcairo size 900,500 font 'sans,10' noenhanced\n";
  s += "set output " + gnuplot_quote(png) + "\n";
  s += "set datafile separator ','\nset key autotitle columnhead\nset logscale y\nset grid\n";
  s += "set title " + gnuplot_quote(title) + "\nset xlabel 'epoch'\n";
  s += "set ylabel 'MSE (standardised units)'\n";
  s += "plot " + gnuplot_quote(csv) + " using 1:2 with lines lw 2, '' using 1:3 with lines lw 2\n";
  return s;
}

// The parts of a checkpoint that must equal a fresh set-up for --resume.
void check_resumable(const trainer::Checkpoint& c, const trainer::HadynetModel& fresh,
                     const trainer::TrainOptions& o, const std::string& path) {
  const auto bad = [&](const std::string& what) {
    throw std::runtime_error(path + ": cannot resume: " + what + " differs from this run");
  };
  if (!(c.model.layout == fresh.layout)) bad("the channel layout");
  if (c.model.states.size() != fresh.states.size()) bad("the set of states");
  for (std::size_t k = 0; k < fresh.states.size(); ++k)
    if (c.model.states[k].name != fresh.states[k].name) bad("the set of states");
  if (!(c.model.params.dims == fresh.params.dims)) bad("the network size");
  if (c.model.train_steps != fresh.train_steps) bad("--window");
  if (c.options.batch != o.batch || c.options.lr != o.lr || c.options.seed != o.seed ||
      c.options.variable_pb != o.variable_pb) {
    bad("--batch, --lr, --seed or --constant-pb");
  }
  const auto hash = c.model.provenance.find("data_hash");
  if (hash == c.model.provenance.end() || hash->second != fresh.provenance.at("data_hash")) {
    bad("the data");
  }
}

}  // namespace

int run_train(int argc, char** argv) {
  Options opt("train",
              "Trains HADYNET (encoder FC+BN+ReLU, LSTM with the PB as input, linear decoder) and one PB per\n"
              "dynamics state (log metadata 'state') jointly with Adam, on windows of --window steps, one per\n"
              "time step, shuffled. The last --held-out fraction of each log's windows is kept out of training\n"
              "and reported as the held-out loss per epoch. A checkpoint OUT.ckpt is written atomically after\n"
              "every epoch; --resume continues an interrupted run exactly. Writes OUT (safetensors, PyTorch\n"
              "names; docs/model-file.md) with the value ranges measured on the training windows (for\n"
              "codegen) and the held-out rows of each log as logs (the residual loop's null), OUT.loss.csv\n"
              "and OUT.loss.png.",
              "LOG|DIR... --out MODEL [options]");
  opt.value("out", "MODEL", "model file to write (.safetensors)");
  opt.value("epochs", "N", "epochs", "200");
  opt.value("batch", "N", "windows per batch", "100");
  opt.value("window", "N", "steps per training window (N_train)", "10");
  opt.value("lr", "X", "Adam learning rate", "0.001");
  opt.value("seed", "N", "seed of the initial weights and of the shuffling", "1");
  opt.value("pb-size", "N", "PB size (entries of each state's PB vector)", "8");
  opt.value("hidden", "N", "LSTM units", "128");
  opt.value("delta-groups", "LIST",
            "channel groups whose step differences join x: a comma-separated list, none, or auto (the logs'\n"
            "'delta_groups' metadata, e.g. l,th in the hand's logs; none when the logs do not name any)",
            "auto");
  opt.value("held-out", "F", "fraction of each log's windows held out for the held-out loss", "0.1");
  opt.value("threads", "N", "training threads (0: every core); results do not depend on it", "0");
  opt.flag("constant-pb", "keep every PB at 0 (the paper's 'constant PB' comparison)");
  opt.flag("resume", "continue from OUT.ckpt (same data and options; --epochs may be raised)");
  opt.flag("quiet", "no per-epoch progress");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (opt.positional().empty() || !opt.has("out")) {
    std::fprintf(stderr, "hadynet train: give logs or folders and --out MODEL (see --help)\n");
    return 2;
  }
  const auto epochs = opt.get_int("epochs", 1, 1000000);
  const auto batch = opt.get_int("batch", 2, 1000000);
  const auto steps = opt.get_int("window", 1, 1000);
  const auto lr = opt.get_double("lr", 1e-12, 10.0);
  const auto seed = opt.get_int("seed", 0, (1ll << 62));
  const auto pb = opt.get_int("pb-size", 1, 1024);
  const auto hidden = opt.get_int("hidden", 1, 65536);
  const auto held_out = opt.get_double("held-out", 0.0, 0.9);
  const auto threads = opt.get_int("threads", 0, 1024);
  if (!epochs || !batch || !steps || !lr || !seed || !pb || !hidden || !held_out || !threads) return 2;
  trainer::set_training_threads(static_cast<int>(*threads));

  const std::string out = opt.get("out");
  const std::string ckpt = out + ".ckpt";
  const bool quiet = opt.has("quiet");
  trainer::TrainOptions options;
  options.epochs = static_cast<int>(*epochs);
  options.batch = static_cast<int>(*batch);
  options.lr = *lr;
  options.seed = static_cast<std::uint64_t>(*seed);
  options.variable_pb = !opt.has("constant-pb");

  try {
    const std::vector<std::string> paths = trainer::expand_log_paths(opt.positional());
    const std::string delta_choice = opt.get("delta-groups");
    const datalog::LogTable first = datalog::read_log(paths.front());
    const datalog::RobotProfile profile = trainer::training_profile(delta_choice, first, paths.front());
    const trainer::FeatureLayout layout = trainer::feature_layout(first, paths.front(), profile.delta_groups);
    std::vector<trainer::LogSequence> sequences = {trainer::log_sequence(first, paths.front(), layout)};
    for (std::size_t i = 1; i < paths.size(); ++i) {  // one table in memory at a time
      const datalog::LogTable table = datalog::read_log(paths[i]);
      trainer::check_profile_metadata(delta_choice, first, paths.front(), table, paths[i]);
      trainer::check_same_period(first, paths.front(), table, paths[i]);
      sequences.push_back(trainer::log_sequence(table, paths[i], layout));
    }

    const trainer::PbStateTable pb_table = trainer::pb_state_table(sequences);
    const std::vector<trainer::PbState>& states = pb_table.states;
    const std::vector<int>& state_of_sequence = pb_table.state_of_sequence;

    const trainer::Normalization norm = trainer::fit_normalization(sequences, layout);
    const trainer::WindowDataset data(sequences, state_of_sequence, layout, norm,
                                      static_cast<int>(*steps));
    const trainer::WindowDataset::Split split = data.split_tail(*held_out);

    trainer::HadynetModel model =
        trainer::new_model(layout, norm, states, static_cast<int>(*pb), static_cast<int>(*hidden),
                           static_cast<int>(*steps), options.seed);
    model.profile = profile;
    model.period_s = datalog::log_dt_s(first, paths.front());
    model.provenance = trainer::training_provenance(paths, HADYNET_GIT_COMMIT, HADYNET_VERSION);
    model.hyper_parameters = trainer::training_hyper_parameters(
        options, {static_cast<int>(*steps), opt.get("lr"), opt.get("held-out"), split.train.size(), split.held_out.size()});

    trainer::TrainingState state;
    if (opt.has("resume")) {
      trainer::Checkpoint c = trainer::load_checkpoint(ckpt);
      check_resumable(c, model, options, ckpt);
      model.params = c.model.params;
      model.bn_batches_tracked = c.model.bn_batches_tracked;
      state = std::move(c.state);
      std::fprintf(stderr, "hadynet train: resuming %s after epoch %d\n", ckpt.c_str(),
                   state.epochs_done);
    } else if (fs::exists(ckpt)) {
      std::fprintf(stderr, "hadynet train: note: overwriting the checkpoint %s (use --resume to continue it)\n",
                   ckpt.c_str());
    }
    std::fprintf(stderr,
                 "hadynet train: %zu logs, %zu states, %zu training + %zu held-out windows of %d steps; "
                 "x %d, u %d, y %d, PB %d, hidden %d; %s PB; %d epochs, %d threads\n",
                 paths.size(), states.size(), split.train.size(), split.held_out.size(),
                 static_cast<int>(*steps), model.params.dims.x, model.params.dims.u,
                 model.params.dims.y, model.params.dims.pb, model.params.dims.hidden,
                 options.variable_pb ? "variable" : "constant", options.epochs, trainer::training_pool().threads());

    const auto started = std::chrono::steady_clock::now();
    const int first_epoch = state.epochs_done + 1;
    trainer::train(model, state, data, split.train, split.held_out, options,
                   [&](const trainer::EpochStats& e) {
                     model.hyper_parameters["epochs_done"] = std::to_string(e.epoch);
                     trainer::save_checkpoint(ckpt, {model, state, options});
                     if (quiet) return;
                     const double elapsed = std::chrono::duration<double>(
                                                std::chrono::steady_clock::now() - started)
                                                .count();
                     const double per_epoch = elapsed / (e.epoch - first_epoch + 1);
                     std::fprintf(stderr,
                                  "epoch %4d/%d  train %.5f  held-out %.5f  %.2f s/epoch  ETA %s\n",
                                  e.epoch, options.epochs, e.train_loss, e.held_out_loss,
                                  e.seconds, duration(per_epoch * (options.epochs - e.epoch)).c_str());
                   });
    model.hyper_parameters["epochs_done"] = std::to_string(state.epochs_done);
    // Value ranges for codegen (docs/codegen.md), over the training windows.
    model.ranges = trainer::measure_ranges(model, data, split.train);
    model.ranges->source = "hadynet train: training windows of " + std::to_string(paths.size()) +
                           " logs (data_hash " + model.provenance.at("data_hash") + ")";
    // The held-out rows as logs: the residual loop's default null (docs/residual.md).
    model.held_out_logs = trainer::held_out_logs(paths, data, split);
    trainer::save_model(out, model);
    const std::string csv = out + ".loss.csv";
    const std::string png = out + ".loss.png";
    write_history(csv, state.history);
    const std::string plot_error =
        run_gnuplot(history_plot(csv, png, fs::path(out).filename().string() + ": loss per epoch"), png);
    if (!plot_error.empty()) std::fprintf(stderr, "hadynet train: warning: %s\n", plot_error.c_str());
    const trainer::EpochStats& last = state.history.back();
    std::printf("wrote %s (train loss %.5f, held-out loss %.5f after %d epochs)\n", out.c_str(),
                last.train_loss, last.held_out_loss, last.epoch);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet train: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
