// hadynet calibrate-detect: contact-detection statistics (docs/method.md, "Detection";
// seed paper III-D). The PB is fitted to the given contact-free logs (or
// chosen with --pb), the N_detect-step prediction errors over them give mu_e
// and Sigma_e, and the threshold C_detect is set by the rule in
// trainer/detection.h unless --threshold is given. Writes a copy of the model
// with the calibration in it.
#include <cstdio>
#include <numeric>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/options.h"
#include "cli/pb_adapt_common.h"
#include "cli/threads_option.h"
#include "cli/trainer_inputs.h"
#include "trainer/detection.h"
#include "trainer/model_file.h"

namespace hadynet::cli {

int run_calibrate_detect(int argc, char** argv) {
  Options opt("calibrate-detect",
              "Calibrates contact detection on contact-free logs (nothing grasped): fits the PB to them\n"
              "(as `adapt`, unless --pb names one), computes the N_detect-step prediction errors e = y_est - y\n"
              "(standardised units), their mean and covariance with a regularised inverse, and the threshold\n"
              "C_detect = 1.5 x the 99.9th percentile of d over these logs (docs/trainer.md). Writes the model\n"
              "with the calibration to --out.",
              "MODEL LOG|DIR... --out MODEL [options]");
  add_adapt_options(opt);
  add_threads_option(opt, "1");
  opt.value("out", "MODEL", "model file to write (may be MODEL itself)");
  opt.value("detect-steps", "N", "N_detect: prediction horizon of detection (<= the model's N_train)", "5");
  opt.value("pb", "PB", "adapt (fit to these logs), zero, a state of the model, or values", "adapt");
  opt.value("threshold", "C", "C_detect instead of the default rule");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (!apply_threads_option(opt, "calibrate-detect")) return 2;
  if (opt.positional().size() < 2 || !opt.has("out")) {
    std::fprintf(stderr, "hadynet calibrate-detect: give MODEL, logs and --out (see --help)\n");
    return 2;
  }
  const auto adapt = adapt_options(opt);
  const auto steps = opt.get_int("detect-steps", 1, 1000);
  std::optional<double> threshold = 0.0;
  if (opt.has("threshold")) threshold = opt.get_double("threshold", 1e-9, 1e12);
  if (!adapt || !steps || !threshold) return 2;
  try {
    trainer::HadynetModel model = trainer::load_model(opt.positional().front());
    if (*steps > model.train_steps) {
      throw std::runtime_error("--detect-steps " + std::to_string(*steps) +
                               " exceeds the model's N_train " + std::to_string(model.train_steps));
    }
    const std::vector<std::string> log_args(opt.positional().begin() + 1, opt.positional().end());
    std::vector<trainer::LogSequence> logs = read_sequences(log_args, model);
    Eigen::VectorXf pb;
    std::string source = std::to_string(logs.size()) + " logs";
    if (opt.get("pb") == "adapt") {
      StateGroup all{"calibration", "", logs};
      const auto adapted = adapt_each_state(model, {all}, parse_start_pbs(model, opt.get("start")), *adapt);
      pb = adapted.front().result.pb;
      std::printf("PB fitted to the calibration logs: loss %.5f -> %.5f, PB %s\n",
                  adapted.front().result.loss.front(), adapted.front().result.loss.back(),
                  format_pb(pb).c_str());
      source += ", PB adapted on them";
    } else {
      pb = parse_pb(model, opt.get("pb"));
      source += ", PB " + opt.get("pb");
    }
    const trainer::DetectionCalibration cal = trainer::calibrate_detection(
        model, logs, pb, static_cast<int>(*steps), *threshold, source);
    std::vector<double> d;
    for (const auto& seq : logs) {
      const Eigen::VectorXd ds = trainer::detection_distances(model, cal, seq);
      d.insert(d.end(), ds.data(), ds.data() + ds.size());
    }
    std::printf("N_detect %d, %ld error samples; d on these logs: median %.2f, 99%% %.2f, 99.9%% %.2f, max %.2f\n",
                cal.steps, cal.samples, trainer::quantile(d, 0.5), trainer::quantile(d, 0.99),
                trainer::quantile(d, 0.999), trainer::quantile(d, 1.0));
    std::printf("C_detect = %.3f%s\n", cal.threshold, opt.has("threshold") ? " (given)" : " (1.5 x 99.9th percentile)");
    model.detection = cal;
    trainer::save_model(opt.get("out"), model);
    std::printf("wrote %s\n", opt.get("out").c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet calibrate-detect: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
