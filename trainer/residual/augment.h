// The second half of the residual loop (docs/residual.md, "--fix"): add the
// attribution's winning effect to the model, fine-tune it, and measure the
// error before and after on held-out data.
//
// Implemented augmentations (docs/residual.md says for each why this one):
//   sensor-delay  time alignment. The delayed channels C (the winner's family,
//                 all with the same delay d) are shifted d steps earlier in the
//                 data, y'_c(s) = y_c(s + d), and the model is fine-tuned on
//                 the aligned logs: it predicts the true-time signal. The
//                 delay is an output transform stated in the model file
//                 (provenance "output_delay"): the measured y_c(t) is the
//                 model's y'_c(t - d). Same dims and weights layout.
//   aux-channel   the aux_* column becomes an observed channel: appended to y
//                 (and so to x, as an input of the encoder). The encoder gets a
//                 zero column for it and the decoder a zero row (the new output
//                 starts at the channel's mean), then the model is fine-tuned.
//                 dims.x and dims.y grow by one.
//   crosstalk     removal of the cross-talk from the data. The winner's target
//                 c picks up k times source s (the fitted gain): the c column
//                 is replaced by y'_c = y_c - k y_s in every row (so in y and
//                 in x), and the model is fine-tuned on these logs: it
//                 predicts the channel without the cross-talk. The cross-talk
//                 is an output transform stated in the model file (provenance
//                 "output_crosstalk"): the measured y_c(t) is the model's
//                 y'_c(t) + k y_s(t), with y_s the model's own prediction of
//                 the source; the inputs get y_c - k y_s. Same dims and
//                 weights layout.
//   friction      a hysteresis state as an input. For every muscle m of the
//                 winner's family, two derived command channels sign_<m>
//                 (direction of motion) and hyst_<m> (sign of the last
//                 non-zero command; trainer/derived_inputs.h) are appended to
//                 u. The LSTM gets zero input columns for them (the model
//                 starts as before), then it is fine-tuned. dims.u grows by
//                 two per muscle; a log needs no new column (they are computed
//                 from the commands).
//   saturation    clipping: every family channel's prediction passes through
//                 min(., R) (max for a lower rail) with its measured rail R
//                 (HadynetModel::output_clips, applied by every prediction),
//                 and the model is fine-tuned on the clipped output (the loss
//                 gradient of a clipped element is 0). Same dims.
//   drift-load,   a drift/bias state b_c(t) = rate * D_c(t) per family channel
//   drift-time    (D: accumulated load sum |y_c| dt, or time), removed from
//                 the data, y'_c = y_c - b_c (in y and x), and added back to the
//                 prediction; the rate is re-estimated before fine-tuning
//                 (refine_drift_rates: the attribution's fitted rate is low,
//                 since the model carries part of a bias over from x_t).
//                 Stated in the model file (provenance "output_drift"). Same
//                 dims.
//
// Held out by time: the first `train_fraction` of each log's rows are the only
// data fine-tuning sees; every number is reported on the remaining rows.
// A causal 1-step prediction of a measured row t in both frames: the model
// starts from frame row t - d - 1 (all of it is known at t - 1: a delayed
// channel's true value at t - d - 1 is its measurement at t - 1) and runs
// d + 1 steps with the logged commands; a delayed channel's measured y_c(t) is
// its first step, every other channel its last. With d = 0 this is the plain
// 1-step prediction of compute_residuals. For crosstalk (d = 0) the measured
// target is the model's y'_c(t) plus k times its prediction of y_s(t), both
// from the same step.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/residual/attribution.h"
#include "trainer/residual/frame_transforms.h"
#include "trainer/residual/residuals.h"
#include "trainer/residual/whiteness.h"

namespace hadynet::trainer::residual {

struct FixOptions {
  double train_fraction = 0.6;  // of each log's rows, from its start: what fine-tuning sees
  int epochs = 20;              // fine-tuning epochs from the current weights (batch norm frozen)
  int batch = 100;
  double lr = 1e-3;             // Adam
  std::uint64_t seed = 1;       // window order
  bool control = true;          // also fine-tune without the augmentation (same data, epochs, seed)
};

// What --fix adds, from the winner and its family.
struct Augmentation {
  EffectKind kind = EffectKind::kSensorDelay;
  std::string effect;              // library name
  std::string description;         // e.g. "time-align fc1, fc2, fc6 by 2 steps"
  // The affected y channels: delayed (delay), the aux channel (aux), the
  // target (crosstalk), the friction targets, the clipped (saturation) or
  // drifting (drift) channels.
  std::vector<std::string> channels;
  int delay = 0;                   // steps (sensor-delay); 0 otherwise
  std::string source;              // crosstalk: the source y channel; empty otherwise
  double gain = 0;                 // crosstalk: fitted gain k (target units per source unit); 0 otherwise
  std::vector<std::string> inputs;  // friction: derived u channels added (sign_u0, hyst_u0, ...)
  std::vector<OutputClip> clips;    // saturation: one per channel
  std::vector<DriftState> drifts;   // drift: one per channel (rates refined by fix())
};
// True for the effects --fix implements (all but input-delay).
bool fix_supported(EffectKind kind);

// The augmentation of the attribution's winner (sensor-delay: every family
// member with the winner's delay). None without a winner.
std::optional<Augmentation> plan_augmentation(const ResidualData& data, const Attribution& attribution);

// Logs in the augmented model's frame: aligned (delayed channels shifted d
// rows earlier, the last d rows dropped); crosstalk: the target column
// replaced by y_c - k y_s (same rows); drift: y_c - b_c (same rows);
// unchanged otherwise (friction's inputs are derived from the commands).
std::vector<LogInput> augmented_logs(const std::vector<LogInput>& logs, const Augmentation& a);

// The model with the augmentation's structural change (aux: one more y and x
// channel; friction: the derived u channels; standardisation of a new channel
// fitted on `train_seqs`, which must hold it), its output clips (saturation)
// and the provenance keys "residual_fix" and "output_delay" (delay),
// "output_crosstalk" (crosstalk) or "output_drift" (drift). Weights otherwise
// unchanged (new inputs get zero weights); detection statistics are dropped
// (they belong to the old weights) and ranges must be re-measured.
HadynetModel augmented_model(const HadynetModel& model, const Augmentation& a,
                             const std::vector<LogSequence>& train_seqs);

// Error of one model on the held-out rows, per channel (physical units).
struct HeldOutError {
  std::vector<std::string> channels;  // the model's y channels
  Eigen::VectorXd rmse;               // sqrt(mean (y - y_hat)^2)
  Eigen::VectorXd fit;                // 100 (1 - ||y - y_hat|| / ||y - mean(y)||), percent
  std::vector<Whiteness> whiteness;   // Ljung-Box etc. of the held-out 1-step residual, per channel
  std::vector<int> inputs_outside;    // lags -L..L outside the 99 % bound, summed over the inputs
  long samples = 0;                   // held-out rows (all logs)
  std::string verdict;                // attribution on the model's own frame (empty: not run)
};

struct FixResult {
  std::string status;  // "no significant effect", "not supported: ...", "fixed"
  std::optional<Augmentation> augmentation;
  bool changed = false;        // a new model was produced
  HadynetModel model;          // the augmented, fine-tuned model (the input model if !changed)
  HeldOutError before, after;  // after: the augmented model (empty if !changed)
  std::optional<HeldOutError> control;  // fine-tuned without augmentation (options.control)
  std::vector<double> loss_history;     // fine-tuning loss per epoch (standardised)
  std::vector<double> fitted_rates;     // drift: the attribution's rate per channel, before refinement
  long train_windows = 0;
};

// The whole --fix step for the analysed `logs` (`data` and `attribution` are
// the analysis of `model` on them, as `hadynet residual` computes them).
// Throws std::runtime_error for logs too short for the split.
FixResult fix(const HadynetModel& model, const std::vector<LogInput>& logs, const ResidualData& data,
              const Attribution& attribution, const FixOptions& options);

}  // namespace hadynet::trainer::residual
