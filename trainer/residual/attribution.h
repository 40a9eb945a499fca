// Attribution (docs/residual.md): every hypothesis of the effect library is
// fitted on the training part of each log and judged on its held-out part.
//
//   1. Split each log's 1-step residual series in time: the first
//      `train_fraction` trains, the rest is held out. Per log, residual and
//      regressors are centred on their training-part means.
//   2. Fit r_c = Z beta + e by least squares with AR(p) errors (two
//      Cochrane-Orcutt passes: OLS, AR(p) fitted to its residual with p by BIC
//      up to max_ar_order, both sides whitened, OLS again) on the training
//      part. Whitening is what makes the test below valid on residuals that
//      are not white (a model's residuals rarely are).
//   3. Held out: with beta fixed, whiten r and Z with the same AR filter and
//      regress the whitened residual on the whitened prediction Z beta (one
//      regressor, an intercept per log). One-sided t-test of a positive slope
//      (equivalently F(1, n - L - 1) with the sign): beta was fixed before the
//      held-out data was seen, so the test has one degree of freedom whatever
//      the number of regressors, and an effect the training part invented
//      does not pass.
//   4. Holm's correction over every hypothesis tested (family-wise error
//      rate alpha); a hypothesis is significant when its adjusted p-value is
//      below alpha AND it explains at least `min_explained` of the held-out
//      residual variance of its channel (in raw units, unwhitened) AND at
//      least `min_explained_std` in the model's standardised units (so that
//      structure in a channel the model already predicts almost perfectly,
//      e.g. an untouched loadcell, does not count as an effect).
//   5. Rank the significant hypotheses by held-out explained variance in
//      standardised units; the first is the winner.
//
// With a calibrated null (NullCalibration: the same hypotheses on clean
// reference logs that are neither the model's training data nor the logs
// under test), the absolute floor of step 4 is replaced by a relative one:
// what a hypothesis explains beyond what it explains on the null, as a share
// of its channel's clean 1-step residual level there (the model's own loss
// on that channel of the reference: excess_share), must reach
// `min_excess_null`, and step 5 ranks by excess_share. Structure the model shows on clean data as well (its
// misfit of new motions, a real rail of the sensor) then counts as the null,
// not as an effect, and the floor means the same on any system's scale.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "trainer/residual/effects.h"
#include "trainer/residual/residuals.h"

namespace hadynet::trainer::residual {

inline constexpr double kDefaultMinExcessNull = 3.0;

struct AttributionOptions {
  double train_fraction = 0.6;  // of each log's residual series, in time
  int max_ar_order = 10;        // whitening filter order (chosen by BIC in 0..max)
  double alpha = 0.01;          // family-wise error rate of the Holm-corrected tests
  double min_explained = 0.10;  // practical floor: share of held-out residual variance
  // Practical floor in standardised units: about twice the largest structure the
  // model's own misfit shows on clean logs of its training states (0.024;
  // docs/residual.md).
  double min_explained_std = 0.05;
  int min_support = 5;          // a regressor must be non-zero on this many training samples
  // With a calibrated null only (it then replaces min_explained_std): the
  // floor of excess_share. About twice the largest excess_share of any
  // hypothesis on clean development logs (1.76; docs/residual.md, "A
  // calibrated null"), as min_explained_std was for the absolute floor.
  double min_excess_null = kDefaultMinExcessNull;
  // With a calibrated null: the floor of excess_share of an upper rail (a
  // saturation at the top of a channel's readings) instead of
  // min_excess_null when lower (unset: min_excess_null); every other
  // condition stays. Set by with_upper_rail_floor() for fix()'s candidates.
  // A rail's family (Attribution::family_of: one effect, any side) then
  // holds the upper rails this floor lets in too, also under a lower rail's
  // lead above the floor.
  std::optional<double> upper_rail_floor;
  // upper_rail_floor is set and below min_excess_null (it then applies).
  bool upper_rail_floor_applies() const { return upper_rail_floor && *upper_rail_floor < min_excess_null; }
};

struct HypothesisResult {
  Hypothesis hypothesis;
  std::string effect;        // library name
  std::string label;         // e.g. "delay = 2 steps on fc3 (gain 0.97)"
  Eigen::VectorXd coef;      // fitted regressor coefficients (target units per regressor unit)
  double parameter = 0;      // main_parameter()
  int ar_order = 0;          // whitening filter order
  long n_train = 0, n_held_out = 0;  // samples used (after whitening drops p per log)
  double explained_train = 0;  // 1 - SS(r - Z beta) / SS(r) on the training part
  double explained = 0;        // the same on the held-out part (can be < 0)
  // Held-out explained variance in the model's standardised units:
  // (SS(r) - SS(r - Z beta)) / n / y_scale_c^2, i.e. how much the effect would
  // lower the channel's standardised 1-step MSE (the model's loss).
  double explained_std = 0;
  bool testable = true;        // false: a regressor is (nearly) constant in the training part
  bool plausible = true;       // the parameter is in the effect's physical domain (effects.h plausible())
  double t_stat = 0, p_value = 1, p_adjusted = 1;
  // With a calibrated null: explained_std of the same hypothesis on the null's
  // held-out part (0 where it is not testable there or explains nothing).
  double null_explained_std = 0;
  // explained_std - null_explained_std (standardised units; explained_std without a null).
  double excess_std = 0;
  // With a null: excess_std / the null's residual level of the target channel
  // (0 where that level is 0). What the floor and the ranking use.
  double excess_share = 0;
  bool significant = false;
};

// The calibrated null: the model's residual on clean reference logs and what
// each hypothesis of the library explains there (docs/residual.md).
struct NullCalibration {
  long logs = 0;
  // Per y channel: mean squared 1-step residual on the held-out part of the
  // reference (each log's rows after train_fraction, centred on its training
  // part's mean), in the model's standardised units.
  Eigen::VectorXd residual_level;
  // Per hypothesis, in the order given to calibrate_null(): its held-out
  // explained_std on the reference, floored at 0 (0 where not testable).
  std::vector<double> explained_std;
};

struct Attribution {
  AttributionOptions options;
  std::optional<NullCalibration> null;  // the floors' null; none: absolute floors
  long tested = 0;                       // family size of the Holm correction
  std::vector<HypothesisResult> ranked;  // significant by explained (desc), then the rest by p
  // The winner (ranked[0]) when it is significant; otherwise none.
  std::optional<HypothesisResult> winner() const;
  // Significant hypotheses of the winner's effect and delay (Hypothesis::delay: 0 for the effects
  // without one), one per target channel (the best), by explained variance: where else the same
  // effect shows.
  std::vector<HypothesisResult> winner_family() const;
  // The same for any significant hypothesis `lead` (its effect and delay).
  std::vector<HypothesisResult> family_of(const HypothesisResult& lead) const;
};

// Fits and tests one hypothesis (steps 1-3; p_adjusted and significant are left for step 4).
HypothesisResult test_hypothesis(const ResidualData& data, const Hypothesis& h, const AttributionOptions& options);

// Two hypotheses of one target fitted together (Cochrane-Orcutt on the
// training part, as test_hypothesis): the held-out t of each one's part of
// the joint prediction against the residual less the other's part. Of two
// correlated sources, it tells which one explains what the other does not.
// {0, 0} when the logs are too short; std::logic_error for two targets.
std::array<double, 2> partial_held_out_t(const ResidualData& data, const Hypothesis& first, const Hypothesis& second,
                                         const AttributionOptions& options);

// The null of `hypotheses` on `reference` (clean logs of the same model and
// channels; never its training data nor the logs under test). Throws
// std::invalid_argument when the reference's channels differ from `data`'s
// (the hypotheses index them).
NullCalibration calibrate_null(const ResidualData& data, const ResidualData& reference,
                               const std::vector<Hypothesis>& hypotheses, const AttributionOptions& options);

// What the floor of step 4 and the ranking of step 5 compare: excess_share
// with a null, else explained_std; and the floor it must reach.
double floor_statistic(const Attribution& attribution, const HypothesisResult& result);
double floor_of(const AttributionOptions& options, bool with_null);

// Every hypothesis, Holm-corrected and ranked (steps 1-5); with `null`
// (from calibrate_null() of the same hypotheses), its relative floors.
Attribution attribute(const ResidualData& data, const std::vector<Hypothesis>& hypotheses,
                      const AttributionOptions& options, const NullCalibration* null = nullptr);

// `attribution` with the floor of excess_share at `min_excess_null` instead:
// the same fits, tests and Holm p-values, significance and ranking (steps 4
// and 5) recomputed. --fix takes its candidates from it with a lower floor
// than the screen's verdict (FixOptions::min_excess_null). Without a
// null, `attribution` unchanged (the absolute floors stay).
Attribution with_null_floor(const Attribution& attribution, double min_excess_null);

// `attribution` with AttributionOptions::upper_rail_floor at `floor`:
// significance and ranking recomputed as with_null_floor() does. Without a
// null, `attribution` unchanged.
Attribution with_upper_rail_floor(const Attribution& attribution, double floor);

}  // namespace hadynet::trainer::residual
