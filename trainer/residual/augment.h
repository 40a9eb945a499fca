// The second half of the residual loop (docs/residual.md, "--fix"): add the
// attribution's winning effect to the model, fine-tune it, and measure the
// error before and after on held-out data.
//
// Implemented augmentations (docs/residual.md says for each why this one).
// Sensor effects become part of the model's sensor model (sensor_model.h:
// the measured channels from the network's; each model is fed logs moved
// into its own frame), so the network keeps its structure:
//   sensor-delay  time alignment of the winner's family (the channels with
//                 the winner's delay d): the model is fine-tuned on logs with
//                 y'_c(s) = y_c(s + d) and predicts the true-time signal.
//   crosstalk     removal: the winner's target c picks up k times source s
//                 (the fitted gain); the model is fine-tuned on y'_c = y_c -
//                 k y_s (in y and x); the measured y_c is y'_c + k y'_s.
//   drift-load,   a bias state b_c(t) = rate * D_c(t) per family channel (D:
//   drift-time    accumulated load sum |y_c| dt, or time), removed from the
//                 data (in y and x) and added to the prediction; the rate is
//                 re-estimated before fine-tuning (the attribution's fit is
//                 low: the model carries part of a bias over from x_t).
//   saturation    clipping: each family channel's prediction passes through
//                 min(., R) (max for a lower rail) at its measured rail R,
//                 applied by every prediction, and the model is fine-tuned on
//                 the clipped output (a clipped element has zero gradient).
// Effects of the dynamics change the network's inputs:
//   aux-channel   the aux_* column becomes an observed channel: appended to y
//                 (and so to x, an encoder input) with a zero encoder column
//                 and a zero decoder row (the new output starts at the
//                 channel's mean). dims.x and dims.y grow by one.
//   friction      a hysteresis state as an input: for every muscle m of the
//                 winner's family, the derived command channels sign_<m>
//                 (direction of motion) and hyst_<m> (sign of the last
//                 non-zero command; trainer/derived_inputs.h) are appended to
//                 u with zero LSTM input weights. dims.u grows by two per
//                 muscle; logs need no new column (they are computed from
//                 the commands).
// Then the model is fine-tuned (batch norm frozen).
//
// Held out by time: the first `train_fraction` of each log's rows are the only
// data fine-tuning sees; every number is reported on the remaining rows.
// Every model (before, fine-tune only, after) is judged on the same rows by
// its causal 1-step prediction of the measured values (held_out.h).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/residual/attribution.h"
#include "trainer/residual/residuals.h"
#include "trainer/residual/fine_tune.h"
#include "trainer/residual/held_out.h"
#include "trainer/residual/statistics.h"
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
  std::string source;              // crosstalk: the winner's source y channel; empty otherwise
  double gain = 0;                 // crosstalk: the winner's fitted gain k (target units per source unit)
  std::vector<SensorCrosstalk> crosstalk;  // crosstalk: the pairs removed (the winner's)
  std::vector<std::string> inputs;  // friction: derived u channels added (sign_u0, hyst_u0, ...)
  std::vector<OutputClip> clips;    // saturation: one per channel
  std::vector<SensorDrift> drifts;   // drift: one per channel (rates refined by fix())
  double period_s = 0;               // drift: the logs' control period (s)
};
// True for the effects --fix implements (all but input-delay).
bool fix_supported(EffectKind kind);

// The augmentation of the attribution's winner, with its family (see each
// effect above). When the winner's effect has no augmentation (input-delay),
// the best significant hypothesis that has one, and the description says so;
// when none has, the winner's (fix() then reports "not supported"). None
// without a winner.
std::optional<Augmentation> plan_augmentation(const ResidualData& data, const Attribution& attribution);

// The sensor model after adding the augmentation's part (delay,
// cross-talk, drift, clips; the others leave it as it is). A delay found in
// the model's frame adds to a channel's existing delay.
SensorModel sensor_after(const SensorModel& before, const Augmentation& a);

// The channel layout after the augmentation: the aux channel appended to y
// (aux-channel), the derived inputs to u (friction); the same otherwise.
FeatureLayout augmented_layout(const FeatureLayout& layout, const Augmentation& a);

// Logs moved into the frame of a model with sensor model `sensor`
// (to_model_frame); the same logs if its frame is the measured one.
std::vector<LogInput> model_frame_logs(const SensorModel& sensor, const std::vector<LogInput>& logs);

// The model with the augmentation's structural change (aux: one more y and x
// channel; friction: the derived u channels; standardisation of a new channel
// fitted on `train_seqs`, which must hold it), its sensor model
// (sensor_after) and the provenance key "residual_fix" (what was added, after
// what an earlier fix added). Weights otherwise unchanged (new inputs get
// zero weights); detection statistics are dropped (they belong to the old
// weights) and ranges must be re-measured.
HadynetModel augmented_model(const HadynetModel& model, const Augmentation& a,
                             const std::vector<LogSequence>& train_seqs);

// The decision (issue 12, "decide by what the fix does"): the screen only
// proposes; the augmented, fine-tuned model is kept only when it beats the
// fine-tune-only control (or, with control off, the unchanged model) on the
// held-out rows of the channels the effect was found on: a one-sided
// Diebold-Mariano test (statistics.h) on the per-row standardised squared
// error, mean over those channels, at the attribution's alpha. Otherwise the
// status is "unexplained structure" and no model is produced.
struct FixResult {
  // "no significant effect", "not supported: ...", "fixed" (confirmed) or
  // "unexplained structure: ..." (tried, not confirmed)
  std::string status;
  std::optional<Augmentation> augmentation;
  bool tried = false;          // the augmented model was fine-tuned and evaluated (after is valid)
  bool changed = false;        // confirmed: a new model was produced
  HadynetModel model;          // the augmented, fine-tuned model (the input model if !changed)
  HeldOutError before, after;  // after: the augmented model (valid if tried)
  std::vector<std::string> confirmation_channels;  // where the effect was found (the test's channels)
  std::string reference;                           // "fine-tuning alone" or "the unchanged model"
  DieboldMariano confirmation;                     // reference's loss minus after's (valid if tried)
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
