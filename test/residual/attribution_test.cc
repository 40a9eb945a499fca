// The effect library's feature tests and the attribution on synthetic
// residuals with a known structure (no model needed): the right hypothesis
// wins with the right parameter, and pure noise gives no significant effect.
// Fixed seeds; tolerances are stated where they appear.
#include "trainer/residual/attribution.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "trainer/residual/augment.h"

namespace hadynet::trainer::residual {
namespace {

constexpr int kRows = 400;

// Two observed channels (a0, a1), two inputs (u0, u1), one aux column: smooth
// random predictions and inputs; the residual is white noise (sd 0.1) plus
// whatever `add` puts in.
template <class Add>
ResidualData synthetic(std::uint64_t seed, Add add, int channels = 2) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  ResidualData d;
  for (int c = 0; c < channels; ++c) d.y_names.push_back("a" + std::to_string(c));
  d.u_names = {"u0", "u1"};
  d.aux_names = {"aux_temp"};
  d.y_scale = Eigen::VectorXd::Ones(channels);
  for (int l = 0; l < 3; ++l) {
    ResidualLog log;
    log.dt_s = 0.2;
    log.seq.file = "log" + std::to_string(l);
    log.seq.u = Eigen::MatrixXd::Zero(2, kRows);
    log.aux = Eigen::MatrixXd::Zero(1, kRows);
    for (int t = 0; t < kRows; ++t) {
      // Piecewise-constant commands (ramps of random sign and length), a slow aux.
      for (int j = 0; j < 2; ++j) log.seq.u(j, t) = (t / (7 + 3 * j)) % 3 == 0 ? 0.0 : ((t / 11 + j) % 2 ? 0.5 : -0.5);
      log.aux(0, t) = std::sin(0.05 * t + l) + 0.3 * std::sin(0.21 * t);
    }
    const int n = kRows - ResidualLog::kFirstRow;
    log.y_hat = Eigen::MatrixXd::Zero(channels, n);
    for (int c = 0; c < channels; ++c) {
      double v = 0;
      for (int j = 0; j < n; ++j) log.y_hat(c, j) = v = 0.9 * v + normal(rng);
    }
    log.r = 0.1 * Eigen::MatrixXd::NullaryExpr(channels, n, [&]() { return normal(rng); });
    add(log);
    log.seq.y = Eigen::MatrixXd::Zero(channels, kRows);
    log.seq.y.rightCols(n) = log.y_hat + log.r;
    d.logs.push_back(std::move(log));
  }
  return d;
}

Attribution run(const ResidualData& d) { return attribute(d, enumerate_hypotheses(d, {}), {}); }

// Channel c reported d steps late, as the model sees it: it predicts y_t from
// the measured y_{t-1}, y_hat_t = y_{t-1} + D_t (D: the change it predicts;
// here c's smooth random series of synthetic()), and the measured change is
// the true change d steps earlier, so r_t gains D_{t-d} - D_t. Built column
// by column, since y_{t-1} (y_hat + r in synthetic(), 0 in row 1) holds the
// residual itself.
void add_sensor_delay(ResidualLog& log, int c, int d) {
  const Eigen::VectorXd change = log.y_hat.row(c).transpose();
  for (Eigen::Index j = 0; j < log.r.cols(); ++j) {
    const double y_previous = j >= 1 ? log.y_hat(c, j - 1) + log.r(c, j - 1) : 0.0;
    log.y_hat(c, j) = y_previous + change(j);
    if (j >= d) log.r(c, j) += change(j - d) - change(j);
  }
}

TEST(Attribution, WhiteNoiseResidualGivesNoSignificantEffect) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const Attribution a = run(synthetic(seed, [](ResidualLog&) {}));
    EXPECT_FALSE(a.winner().has_value()) << "seed " << seed << ": " << a.ranked.front().label;
    EXPECT_GT(a.tested, 30);
  }
}

TEST(Attribution, SensorDelayWinsWithItsDelay) {
  // a1 is reported 2 steps late.
  const Attribution a = run(synthetic(4, [](ResidualLog& log) { add_sensor_delay(log, 1, 2); }));
  ASSERT_TRUE(a.winner().has_value());
  const auto w = *a.winner();
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kSensorDelay);
  EXPECT_EQ(w.hypothesis.delay, 2);
  EXPECT_EQ(w.hypothesis.target, 1);
  EXPECT_NEAR(w.parameter, 1.0, 0.05);  // gain 1: the whole residual is the delay
}

TEST(Attribution, FrictionWinsWithItsMuscleAndMagnitude) {
  // a0 carries -0.3 while u1 moves +, +0.3 while it moves - (and holds the last sign).
  const Attribution a = run(synthetic(5, [](ResidualLog& log) {
    double state = 0;
    for (Eigen::Index j = 0; j < log.r.cols(); ++j) {
      const double u = log.seq.u(1, ResidualLog::row(static_cast<int>(j)) - 1);
      if (u != 0) state = u > 0 ? 1 : -1;
      log.r(0, j) += -0.3 * state;
    }
  }));
  ASSERT_TRUE(a.winner().has_value());
  const auto w = *a.winner();
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kFriction);
  EXPECT_EQ(w.hypothesis.target, 0);
  EXPECT_EQ(w.hypothesis.source, 1);
  EXPECT_NEAR(w.parameter, -0.3, 0.03);  // 10 %: noise sd 0.1 over ~500 training samples
}

// An absolute command (a level: here u1 made a set point that rises and
// falls from 2, never crossing 0) moves when it changes: friction follows the
// sign of its change and that change's hysteresis state, not its own sign.
TEST(Attribution, FrictionOfAnAbsoluteCommandFollowsItsChange) {
  const auto levels = [](ResidualLog& log) {
    double level = 2;
    for (Eigen::Index t = 0; t < log.seq.u.cols(); ++t) log.seq.u(1, t) = level += 0.2 * log.seq.u(1, t);
  };
  const ResidualData d = synthetic(5, [&](ResidualLog& log) {
    levels(log);
    double state = 0;
    for (Eigen::Index j = 0; j < log.r.cols(); ++j) {
      const Eigen::Index t = ResidualLog::row(static_cast<int>(j));
      const double change = log.seq.u(1, t - 1) - log.seq.u(1, t - 2);
      if (change != 0) state = change > 0 ? 1 : -1;
      log.r(0, j) += -0.3 * state;
    }
  });
  ASSERT_GT(d.logs.front().seq.u.row(1).minCoeff(), 0.0);
  // Declared absolute (the logs' absolute_groups, or the option): named, with the magnitude.
  for (const bool by_option : {false, true}) {
    ResidualData declared = d;
    LibraryOptions o;
    if (by_option)
      o.absolute_groups = std::vector<std::string>{"u"};
    else
      declared.u_absolute = {false, true};
    const Attribution a = attribute(declared, enumerate_hypotheses(declared, o), {});
    ASSERT_TRUE(a.winner().has_value());
    const auto w = *a.winner();
    EXPECT_EQ(w.hypothesis.kind, EffectKind::kFriction) << w.label;
    EXPECT_EQ(w.hypothesis.source, 1) << w.label;
    EXPECT_TRUE(w.hypothesis.of_change) << w.label;
    EXPECT_NEAR(w.parameter, -0.3, 0.03) << w.label;  // as the incremental case above
  }
  // Undeclared, u1's sign is +1 throughout: its friction is not testable (the screen names an input
  // delay instead, whose regressors u(t-1-d) - u(t-1) hold the change).
  const Attribution undeclared = run(d);
  for (const auto& r : undeclared.ranked)
    if (r.hypothesis.kind == EffectKind::kFriction && r.hypothesis.source == 1) {
      EXPECT_FALSE(r.testable) << r.label;
    }
  if (undeclared.winner()) {
    EXPECT_NE(undeclared.winner()->hypothesis.kind, EffectKind::kFriction);
  }
}

TEST(Attribution, AuxChannelAndCrosstalkWin) {
  const Attribution aux = run(synthetic(6, [](ResidualLog& log) {
    for (Eigen::Index j = 0; j < log.r.cols(); ++j) log.r(1, j) += 0.4 * log.aux(0, ResidualLog::row(static_cast<int>(j)));
  }));
  ASSERT_TRUE(aux.winner().has_value());
  EXPECT_EQ(aux.winner()->hypothesis.kind, EffectKind::kAuxChannel);
  EXPECT_EQ(aux.winner()->hypothesis.target, 1);
  EXPECT_NEAR(aux.winner()->parameter, 0.4, 0.04);

  // a0 picks up 0.3 of a1's measured value (y_hat + r of a1).
  const Attribution xt = run(synthetic(7, [](ResidualLog& log) { log.r.row(0) += 0.3 * (log.y_hat.row(1) + log.r.row(1)); }));
  ASSERT_TRUE(xt.winner().has_value());
  EXPECT_EQ(xt.winner()->hypothesis.kind, EffectKind::kCrosstalk);
  EXPECT_EQ(xt.winner()->hypothesis.source, 1);
  EXPECT_EQ(xt.winner()->hypothesis.target, 0);
  EXPECT_NEAR(xt.winner()->parameter, 0.3, 0.03);

  // The same structure with gain -0.3 is outside cross-talk's domain (a
  // fraction, 0 < gain < 1): tested, fitted and implausible, so never the
  // winner, although it is strong.
  const Attribution neg =
      run(synthetic(7, [](ResidualLog& log) { log.r.row(0) -= 0.3 * (log.y_hat.row(1) + log.r.row(1)); }));
  int found = 0;
  for (const auto& r : neg.ranked) {
    if (r.hypothesis.kind != EffectKind::kCrosstalk || r.hypothesis.target != 0 || r.hypothesis.source != 1) continue;
    ++found;
    EXPECT_NEAR(r.parameter, -0.3, 0.03);
    EXPECT_FALSE(r.plausible);
    EXPECT_LT(r.p_adjusted, 1e-6);
    EXPECT_FALSE(r.significant);
  }
  EXPECT_EQ(found, 1);
  if (neg.winner()) {
    EXPECT_NE(neg.winner()->hypothesis.kind, EffectKind::kCrosstalk) << neg.winner()->label;
  }
}

// A network that carries a share rho of its measured input over leaves
// k y_s(t) - rho k y_s(t-1) of a cross-talk in its residual: the gain is
// still k (with y_s(t) alone it read k (1 - rho corr(y_s(t), y_s(t-1)))).
TEST(Attribution, CrosstalkGainSurvivesWhatTheNetworkCarriesOver) {
  const Attribution xt = run(synthetic(7, [](ResidualLog& log) {
    const Eigen::RowVectorXd source = log.y_hat.row(1) + log.r.row(1);
    for (Eigen::Index j = 1; j < log.r.cols(); ++j) log.r(0, j) += 0.3 * (source(j) - 0.6 * source(j - 1));
  }));
  ASSERT_TRUE(xt.winner().has_value());
  EXPECT_EQ(xt.winner()->hypothesis.kind, EffectKind::kCrosstalk);
  EXPECT_EQ(xt.winner()->hypothesis.source, 1);
  EXPECT_NEAR(xt.winner()->parameter, 0.3, 0.03);  // the same 10 % as the plain pick-up above
}

// Two correlated sources of one target (a2 reads 0.8 of a1's level and a
// level of its own; a0 picks up 0.3 of the measured a1): alone, each
// explains a0 (t above 10), but fitted together only the source a0 really
// picks up keeps its part: its partial held-out t stays above 10 and the
// other's falls below 3 (a t of 3 is p ~ 0.001 at these ~450 held-out
// rows), in either order of the two.
TEST(Attribution, OfTwoCorrelatedSourcesThePartialTKeepsTheOneTheTargetPicksUp) {
  const ResidualData d = synthetic(
      9,
      [](ResidualLog& log) {
        log.y_hat.row(2) = 0.8 * log.y_hat.row(1) + 0.6 * log.y_hat.row(2);
        log.r.row(0) += 0.3 * (log.y_hat.row(1) + log.r.row(1));
      },
      3);
  const Hypothesis from_a1{EffectKind::kCrosstalk, 0, 1, 0, 0, 0}, from_a2{EffectKind::kCrosstalk, 0, 2, 0, 0, 0};
  const AttributionOptions options;
  EXPECT_GT(test_hypothesis(d, from_a1, options).t_stat, 10);
  EXPECT_GT(test_hypothesis(d, from_a2, options).t_stat, 10);
  const std::array<double, 2> t = partial_held_out_t(d, from_a1, from_a2, options);
  EXPECT_GT(t[0], 10);
  EXPECT_LT(std::abs(t[1]), 3);
  const std::array<double, 2> mirrored = partial_held_out_t(d, from_a2, from_a1, options);
  EXPECT_NEAR(mirrored[0], t[1], 1e-6 * std::abs(t[0]));
  EXPECT_NEAR(mirrored[1], t[0], 1e-6 * std::abs(t[0]));
  EXPECT_THROW(partial_held_out_t(d, from_a1, Hypothesis{EffectKind::kCrosstalk, 1, 2, 0, 0, 0}, options),
               std::logic_error);
}

// The plan of a cross-talk led by the decoy of the test above (fc2 -> fc0,
// both sources significant in fc0's group) removes the pair of the source
// fc0 really picks up, fc1, with that pair's gain (0.3 within the 10 % of
// the plain pick-up above). Before stop 76 the plan took the lead's pair.
TEST(Attribution, ACrossTalkPlanTakesItsTargetsClearerOfTwoSources) {
  ResidualData d = synthetic(
      9,
      [](ResidualLog& log) {
        log.y_hat.row(2) = 0.8 * log.y_hat.row(1) + 0.6 * log.y_hat.row(2);
        log.r.row(0) += 0.3 * (log.y_hat.row(1) + log.r.row(1));
      },
      3);
  d.y_names = {"fc0", "fc1", "fc2"};
  const Attribution attribution = run(d);
  const auto decoy = std::find_if(attribution.ranked.begin(), attribution.ranked.end(), [](const HypothesisResult& r) {
    return r.hypothesis.kind == EffectKind::kCrosstalk && r.hypothesis.target == 0 && r.hypothesis.source == 2;
  });
  ASSERT_NE(decoy, attribution.ranked.end());
  ASSERT_TRUE(decoy->significant) << decoy->label;
  Augmentation a;
  a.kind = EffectKind::kCrosstalk;
  effect_info(a.kind).plan(d, attribution, *decoy, a);
  const auto* removal = std::get_if<CrosstalkRemoval>(&a.change);
  ASSERT_NE(removal, nullptr);
  ASSERT_FALSE(removal->pairs.empty());
  EXPECT_EQ(removal->pairs.front().target, "fc0");
  EXPECT_EQ(removal->pairs.front().source, "fc1") << a.description;
  EXPECT_NEAR(removal->pairs.front().gain, 0.3, 0.03);
}

// Cross-talk sources by default: the target's group, and other groups in
// its unit; a group without a declared unit only within itself.
TEST(Attribution, CrosstalkSourcesAreTheGroupAndTheUnit) {
  ResidualData d = synthetic(7, [](ResidualLog&) {});
  d.y_names = {"f0", "f1", "fc0", "l0"};
  d.y_units = channel_units("t=s f=N fc=N", d.y_names);
  EXPECT_EQ(d.y_units, (std::vector<std::string>{"N", "N", "N", ""}));
  EXPECT_EQ(channel_units("f=N f1=kN", {"f0", "f1", "x"}), (std::vector<std::string>{"N", "kN", ""}));
  auto sources = [&](CrosstalkSources which, int target) {
    std::set<int> out;
    std::vector<Hypothesis> hs;
    LibraryOptions o;
    o.crosstalk_sources = which;
    effect_info(EffectKind::kCrosstalk).enumerate(d, o, target, hs);
    for (const auto& h : hs) out.insert(h.source);
    return out;
  };
  EXPECT_EQ(sources(CrosstalkSources::kSameUnit, 2), (std::set<int>{0, 1}));  // fc0 <- f0, f1 (N)
  EXPECT_EQ(sources(CrosstalkSources::kSameUnit, 3), (std::set<int>{}));      // l0: no unit, alone in its group
  EXPECT_EQ(sources(CrosstalkSources::kSameGroup, 2), (std::set<int>{}));
  EXPECT_EQ(sources(CrosstalkSources::kSameGroup, 0), (std::set<int>{1}));
  EXPECT_EQ(sources(CrosstalkSources::kAll, 3), (std::set<int>{0, 1, 2}));
}

// A rail is where the signal sits: a channel's extreme reached in a few rows
// only is no saturation candidate (LibraryOptions::min_rail_share).
TEST(Attribution, AnExtremeReachedOnceIsNoRail) {
  const ResidualData d = synthetic(8, [](ResidualLog&) {});
  int rails = 0;
  for (const auto& h : enumerate_hypotheses(d, {}))
    if (h.kind == EffectKind::kSaturation && h.target == 0) ++rails;
  // AR(1) predictions plus noise: a continuous signal, its top and bottom
  // 5 % of the range hold a handful of rows.
  EXPECT_EQ(rails, 0);
  LibraryOptions every_extreme;
  every_extreme.min_rail_share = 0;
  every_extreme.rail_band = 0;
  int forced = 0;
  for (const auto& h : enumerate_hypotheses(d, every_extreme))
    if (h.kind == EffectKind::kSaturation && h.target == 0) ++forced;
  EXPECT_EQ(forced, 0);  // still needs 5 rows at the extreme
}

// Friction is tested on the logged commands only: after a --fix the model's
// u also holds derived channels (a dead time's lag2_u0, friction's sign_u1
// and hyst_u1), whose own sign and hysteresis cannot be derived from a log
// (round 2 after a dead time failed on "no column 'sign_lag2_u4'").
TEST(Attribution, FrictionIsTestedOnTheLoggedCommandsOnly) {
  ResidualData d = synthetic(8, [](ResidualLog&) {});
  d.u_names = {"u0", "u1", "lag2_u0", "sign_u1", "hyst_u1"};
  for (auto& log : d.logs) {
    Eigen::MatrixXd u = Eigen::MatrixXd::Zero(5, log.seq.u.cols());
    u.topRows(2) = log.seq.u;
    log.seq.u = u;
  }
  std::set<int> sources;
  for (const auto& h : enumerate_hypotheses(d, {}))
    if (h.kind == EffectKind::kFriction) sources.insert(h.source);
  EXPECT_EQ(sources, (std::set<int>{0, 1}));
}

TEST(Attribution, SaturationAndDriftWin) {
  // a0 is clipped at +1.5: measured = min(y_hat, 1.5) (rail = the largest measured value).
  const Attribution sat = run(synthetic(8, [](ResidualLog& log) {
    for (Eigen::Index j = 0; j < log.r.cols(); ++j) log.r(0, j) = std::min(log.y_hat(0, j), 1.5) - log.y_hat(0, j);
  }));
  ASSERT_TRUE(sat.winner().has_value());
  EXPECT_EQ(sat.winner()->hypothesis.kind, EffectKind::kSaturation);
  EXPECT_EQ(sat.winner()->hypothesis.side, +1);
  EXPECT_NEAR(sat.winner()->hypothesis.rail, 1.5, 1e-9);
  // The same rows where the model's frame reads a0 through a curve, a
  // cross-talk or a drift (ResidualData::y_frame_transformed): a level there
  // is no sensor reading, so no rail is searched on it.
  ResidualData transformed = synthetic(8, [](ResidualLog& log) {
    for (Eigen::Index j = 0; j < log.r.cols(); ++j) log.r(0, j) = std::min(log.y_hat(0, j), 1.5) - log.y_hat(0, j);
  });
  transformed.y_frame_transformed = {true, false};
  for (const auto& h : enumerate_hypotheses(transformed, {}))
    EXPECT_FALSE(h.kind == EffectKind::kSaturation && h.target == 0) << h.rail;

  // a1 drifts by 0.01 per second (a bias growing with time since the log's start).
  const Attribution drift = run(synthetic(9, [](ResidualLog& log) {
    for (Eigen::Index j = 0; j < log.r.cols(); ++j) log.r(1, j) += 0.01 * ResidualLog::row(static_cast<int>(j)) * log.dt_s;
  }));
  ASSERT_TRUE(drift.winner().has_value());
  EXPECT_EQ(drift.winner()->hypothesis.kind, EffectKind::kDriftTime);
  EXPECT_EQ(drift.winner()->hypothesis.target, 1);
  EXPECT_NEAR(drift.winner()->parameter, 0.01, 0.002);
}

TEST(Attribution, ConstantRegressorIsNotTestable) {
  ResidualData d = synthetic(10, [](ResidualLog&) {});
  for (auto& log : d.logs) log.seq.u.row(0).setZero();  // u0 never moves: no friction test possible
  const HypothesisResult r = test_hypothesis(d, {EffectKind::kFriction, 0, 0, 0, 0, 0}, {});
  EXPECT_FALSE(r.testable);
  EXPECT_EQ(r.p_value, 1.0);
}


// ---- The calibrated null (attribution.h; docs/residual.md, "A calibrated null") ----

// The residual of a system whose model is very good (noise sd 0.001, as the
// Cascaded Tanks' whole 1-step residual is about 0.0025 standardised units)
// with a1 reported 2 steps late, predictions and residual at one scale.
ResidualData scaled(std::uint64_t seed, double scale, bool delayed) {
  return synthetic(seed, [&](ResidualLog& log) {
    log.r *= scale;
    log.y_hat *= scale;  // the whole data at this scale: the delay's regressor holds y_hat and r
    if (delayed) add_sensor_delay(log, 1, 2);
  });
}

Attribution run_with_null(const ResidualData& d, const ResidualData& reference) {
  const auto hypotheses = enumerate_hypotheses(d, {});
  const NullCalibration null = calibrate_null(d, reference, hypotheses, {});
  return attribute(d, hypotheses, {}, &null);
}

// The issue-12 finding on measured data: an absolute floor in standardised
// units can never be reached by a model whose whole residual is far below
// it. Relative to the model's residual on a clean null, the same effect is
// named, and the verdict does not depend on the scale: excess_share is a
// ratio of variances of the same units (equal to 1e-9 relative: rounding).
TEST(CalibratedNull, AnEffectOfATinyResidualIsNamedRelativeToTheNullAtAnyScale) {
  const Attribution absolute = run(scaled(21, 0.01, true));
  ASSERT_FALSE(absolute.ranked.empty());
  EXPECT_LT(absolute.ranked.front().p_adjusted, 1e-6);  // the structure is there...
  EXPECT_FALSE(absolute.winner().has_value());          // ...and under the absolute floor
  double share[2] = {0, 0};
  const double scales[2] = {0.01, 1.0};
  for (int i = 0; i < 2; ++i) {
    const Attribution a = run_with_null(scaled(21, scales[i], true), scaled(22, scales[i], false));
    ASSERT_TRUE(a.null.has_value());
    ASSERT_TRUE(a.winner().has_value()) << "scale " << scales[i];
    EXPECT_EQ(a.winner()->hypothesis.kind, EffectKind::kSensorDelay);
    EXPECT_EQ(a.winner()->hypothesis.delay, 2);
    EXPECT_EQ(a.winner()->hypothesis.target, 1);
    share[i] = a.winner()->excess_share;
  }
  EXPECT_GT(share[0], kDefaultMinExcessNull);
  EXPECT_NEAR(share[0] / share[1], 1.0, 1e-9);
}

// Clean data on both sides: nothing passes the relative floor (white noise
// has no structure; three seeds).
TEST(CalibratedNull, CleanLogsAgainstACleanNullGiveNothing) {
  for (std::uint64_t seed : {23, 24, 25}) {
    const Attribution a = run_with_null(scaled(seed, 0.01, false), scaled(seed + 10, 0.01, false));
    EXPECT_FALSE(a.winner().has_value()) << "seed " << seed << ": " << a.ranked.front().label;
  }
}

// Structure the model shows on its clean null as well (a misfit of the
// model, a rail the sensor really has) is the null, not an effect: a
// friction-like residual on a0 in both wins without a null and is discounted
// with it (what it explains on the null is subtracted).
TEST(CalibratedNull, StructureTheNullAlsoShowsIsNoEffect) {
  const auto friction = [](ResidualLog& log) {
    double state = 0;
    for (Eigen::Index j = 0; j < log.r.cols(); ++j) {
      const double u = log.seq.u(1, ResidualLog::row(static_cast<int>(j)) - 1);
      if (u != 0) state = u > 0 ? 1 : -1;
      log.r(0, j) += -0.3 * state;
    }
  };
  const ResidualData test = synthetic(26, friction);
  const Attribution without = run(test);
  ASSERT_TRUE(without.winner().has_value());
  EXPECT_EQ(without.winner()->hypothesis.kind, EffectKind::kFriction);
  const Attribution with = run_with_null(test, synthetic(27, friction));
  EXPECT_FALSE(with.winner().has_value()) << with.ranked.front().label;
  for (const auto& r : with.ranked) {
    if (r.hypothesis.kind != EffectKind::kFriction || r.hypothesis.target != 0 || r.hypothesis.source != 1) continue;
    EXPECT_GT(r.null_explained_std, 0.5 * r.explained_std);
  }
}

// with_null_floor (--fix's candidates below the screen's floor) is attribute()
// at that floor: the same significant hypotheses in the same order, the
// fits and p-values untouched, at floors below, at and above the default; a
// lower floor lets more in. Without a null the absolute floors stay.
TEST(CalibratedNull, AnotherFloorRanksAsAttributeAtThatFloor) {
  const ResidualData test = scaled(21, 1.0, true);
  const ResidualData reference = scaled(22, 1.0, false);
  const auto hypotheses = enumerate_hypotheses(test, {});
  const NullCalibration null = calibrate_null(test, reference, hypotheses, {});
  const Attribution screen = attribute(test, hypotheses, {}, &null);
  const auto significant = [](const Attribution& a) {
    std::vector<std::string> labels;
    for (const auto& r : a.ranked)
      if (r.significant) labels.push_back(r.label);
    return labels;
  };
  // The second largest share of the hypotheses that pass every other test:
  // a floor there lets fewer in than a floor of 0.
  std::vector<double> shares;
  for (const auto& r : with_null_floor(screen, 0.0).ranked)
    if (r.significant) shares.push_back(r.excess_share);
  ASSERT_GE(shares.size(), 2u);
  const double between = shares[1];
  std::size_t at_zero = 0, at_between = 0;
  for (const double floor : {0.0, 0.5, 1.0, kDefaultMinExcessNull, between, 10.0, 1e6}) {
    AttributionOptions o;
    o.min_excess_null = floor;
    const Attribution direct = attribute(test, hypotheses, o, &null);
    const Attribution refloored = with_null_floor(screen, floor);
    EXPECT_EQ(significant(refloored), significant(direct)) << "floor " << floor;
    EXPECT_EQ(refloored.options.min_excess_null, floor);
    EXPECT_EQ(refloored.tested, screen.tested);
    if (floor == 0.0) at_zero = significant(direct).size();
    if (floor == between) at_between = significant(direct).size();
  }
  EXPECT_GT(at_zero, at_between);  // the floor decides something here
  EXPECT_GE(at_between, 1u);
  EXPECT_TRUE(significant(with_null_floor(screen, 1e6)).empty());
  // Fits and tests as they were: copied, not recomputed, so equal to the bit.
  for (const auto& r : with_null_floor(screen, 0.0).ranked) {
    const auto same = std::find_if(screen.ranked.begin(), screen.ranked.end(),
                                   [&](const HypothesisResult& s) { return s.label == r.label; });
    ASSERT_NE(same, screen.ranked.end());
    EXPECT_EQ(same->p_adjusted, r.p_adjusted);
    EXPECT_EQ(same->excess_share, r.excess_share);
  }
  const Attribution absolute = run(test);
  EXPECT_EQ(significant(with_null_floor(absolute, 0.0)), significant(absolute));
}

// with_upper_rail_floor (--fix's candidates, FixOptions::upper_rail_floor):
// an upper rail below the floor of excess_share passes at the rail's own
// floor when every other test of the screen passes; a lower rail, another
// effect, a rail below the share of the residual variance (min_explained),
// above Holm's level or with an implausible gain, and a rail below its own
// floor do not; one at its own floor does. Hand-made results (the floors' arithmetic alone), ranked
// significant first. Without a null, nothing changes.
TEST(CalibratedNull, AnUpperRailBelowTheFloorPassesAtItsOwnFloor) {
  const auto result = [](const std::string& label, EffectKind kind, int side, double excess_share) {
    HypothesisResult r;
    r.label = label;
    r.hypothesis.kind = kind;
    r.hypothesis.side = side;
    r.testable = true;
    r.p_value = 1e-12;
    r.p_adjusted = 1e-10;
    r.explained = 0.5;
    r.excess_share = excess_share;
    return r;
  };
  Attribution screen;
  screen.null = NullCalibration{};
  screen.tested = 8;
  screen.ranked.push_back(result("upper rail", EffectKind::kSaturation, +1, 0.3));
  screen.ranked.push_back(result("lower rail", EffectKind::kSaturation, -1, 0.3));
  screen.ranked.push_back(result("delay", EffectKind::kSensorDelay, 0, 0.3));
  screen.ranked.push_back(result("upper rail, little variance", EffectKind::kSaturation, +1, 0.3));
  screen.ranked.back().explained = 0.05;  // below min_explained (0.1)
  screen.ranked.push_back(result("upper rail, above Holm's level", EffectKind::kSaturation, +1, 0.3));
  screen.ranked.back().p_adjusted = 0.02;
  screen.ranked.push_back(result("upper rail, implausible", EffectKind::kSaturation, +1, 0.3));
  screen.ranked.back().plausible = false;
  screen.ranked.push_back(result("upper rail, below the null", EffectKind::kSaturation, +1, -0.1));
  screen.ranked.push_back(result("upper rail, above the floor", EffectKind::kSaturation, +1, 4.0));
  const auto significant = [](const Attribution& a) {
    std::vector<std::string> labels;
    for (const auto& r : a.ranked)
      if (r.significant) labels.push_back(r.label);
    return labels;
  };
  const Attribution at_floor = with_null_floor(screen, kDefaultMinExcessNull);
  EXPECT_EQ(significant(at_floor), std::vector<std::string>{"upper rail, above the floor"});
  const Attribution rails = with_upper_rail_floor(at_floor, 0.0);
  EXPECT_EQ(significant(rails), (std::vector<std::string>{"upper rail, above the floor", "upper rail"}));
  EXPECT_EQ(rails.options.upper_rail_floor, std::optional<double>(0.0));
  EXPECT_EQ(rails.options.min_excess_null, kDefaultMinExcessNull);
  EXPECT_TRUE(rails.ranked[1].significant);   // the significant first, by excess share
  EXPECT_FALSE(rails.ranked[2].significant);
  EXPECT_EQ(significant(with_upper_rail_floor(at_floor, 0.5)), significant(at_floor));  // 0.3 < 0.5
  // At the rail's floor itself a rail passes (>=, as every floor of excess share).
  EXPECT_EQ(significant(with_upper_rail_floor(at_floor, 0.3)), significant(rails));
  // A rail's floor equal to the others' is no other floor: the excess of 0.3 stays below 1.
  EXPECT_EQ(significant(with_upper_rail_floor(with_null_floor(screen, 1.0), 1.0)),
            std::vector<std::string>{"upper rail, above the floor"});
  // A rail's floor above the others' changes nothing (it is never higher).
  EXPECT_EQ(significant(with_upper_rail_floor(with_null_floor(screen, 0.2), 1.0)),
            significant(with_null_floor(screen, 0.2)));
  Attribution absolute = screen;
  absolute.null.reset();
  EXPECT_EQ(significant(with_upper_rail_floor(absolute, 0.0)), significant(absolute));
}

TEST(CalibratedNull, AReferenceWithOtherChannelsIsRefused) {
  const ResidualData d = scaled(28, 1.0, false);
  ResidualData other = scaled(29, 1.0, false);
  other.y_names = {"a0", "b1"};
  EXPECT_THROW(calibrate_null(d, other, enumerate_hypotheses(d, {}), {}), std::invalid_argument);
}

}  // namespace
}  // namespace hadynet::trainer::residual
