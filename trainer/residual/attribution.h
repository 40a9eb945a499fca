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
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "trainer/residual/effects.h"
#include "trainer/residual/residuals.h"

namespace hadynet::trainer::residual {

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
  bool significant = false;
};

struct Attribution {
  AttributionOptions options;
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

// Every hypothesis, Holm-corrected and ranked (steps 1-5).
Attribution attribute(const ResidualData& data, const std::vector<Hypothesis>& hypotheses,
                      const AttributionOptions& options);

}  // namespace hadynet::trainer::residual
