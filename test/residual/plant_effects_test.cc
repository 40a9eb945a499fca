// The residual analysis on MuJoCo plant logs (docs/residual.md, "Measured
// results"): the build's model (trained on clean paper-preset logs) analyses
// logs of states it knows, recorded with one of the plant's effects switched
// on and declared nowhere. The analysis must name the effect (and its
// channel and parameter where the plant has one), and report nothing
// significant on clean logs of the same states.
//
// Effects too weak at the plant's default strength to leave a detectable
// residual in 300-step logs (drift 0.004 N/(N s), saturation at 3 N; numbers
// in docs/residual.md) are tested at a documented stronger setting; the
// default drift is also tested on 1000-step logs, with clean 1000-step logs
// as its null.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <tuple>
#include <variant>

#include "datalog/log_reader.h"
#include "trainer/derived_inputs.h"
#include "test/residual/plant_logs.h"
#include "trainer/derived_inputs.h"
#include "trainer/residual/analysis.h"
#include "trainer/residual/attribution.h"
#include "trainer/residual/augment.h"
#include "trainer/residual/effects.h"
#include "trainer/residual/rated_ranges.h"

namespace hadynet::test {
namespace {

using namespace trainer::residual;
using trainer::channel_group;

struct Outcome {
  ResidualData data;
  Attribution attribution;
};

Outcome analyse(const std::string& effect, int steps = 300, std::uint64_t seed = 1) {
  Outcome o;
  o.data = compute_residuals(build_model(), plant_logs(effect, steps, seed), "auto");
  o.attribution = attribute(o.data, enumerate_hypotheses(o.data, {}), {});
  // The measured numbers, for docs/residual.md.
  std::printf("effect '%s', %d steps: %ld hypotheses; top of the ranking:\n", effect.c_str(), steps,
              o.attribution.tested);
  for (std::size_t i = 0; i < 3 && i < o.attribution.ranked.size(); ++i) {
    const auto& r = o.attribution.ranked[i];
    std::printf("  %c %-58s share %.3f std %.4f p(Holm) %.2g\n", r.significant ? '*' : ' ', r.label.c_str(),
                r.explained, r.explained_std, r.p_adjusted);
  }
  return o;
}

std::string name_of(const Outcome& o, int channel) { return o.data.y_names[static_cast<std::size_t>(channel)]; }

TEST(PlantEffects, CleanLogsReportNothingSignificant) {
  const Outcome o = analyse("");
  EXPECT_FALSE(o.attribution.winner().has_value()) << o.attribution.ranked.front().label;
  EXPECT_GT(o.attribution.tested, 500);
}

// The winner is a sensor delay of `steps` on a loadcell, and every channel
// on which the same delay is significant is a loadcell.
void expect_loadcell_delay_wins(const Outcome& o, int steps) {
  ASSERT_TRUE(o.attribution.winner().has_value());
  const auto w = *o.attribution.winner();
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kSensorDelay) << w.label;
  EXPECT_EQ(w.hypothesis.delay, steps) << w.label;
  EXPECT_EQ(channel_group(name_of(o, w.hypothesis.target)), "fc") << w.label;
  for (const auto& r : o.attribution.winner_family()) EXPECT_EQ(channel_group(name_of(o, r.hypothesis.target)), "fc");
}

// Every significant sensor delay is either declined because commands act
// late, or planned as their dead time (the commands d steps earlier as
// inputs), never as a time alignment.
void expect_every_sensor_delay_is_a_dead_time(const Outcome& o) {
  bool seen = false;
  for (const auto& r : o.attribution.ranked) {
    if (!r.significant || r.hypothesis.kind != EffectKind::kSensorDelay) continue;
    seen = true;
    const std::string why = why_not_fixable(o.data, o.attribution, r);
    if (!why.empty()) {
      EXPECT_NE(why.find("commands acting late"), std::string::npos) << r.label << ": " << why;
      continue;
    }
    Augmentation a;
    a.kind = r.hypothesis.kind;
    effect_info(a.kind).plan(o.data, o.attribution, r, a);
    EXPECT_EQ(a.kind, EffectKind::kInputDelay) << r.label << ": " << a.description;
    EXPECT_TRUE(std::holds_alternative<DerivedCommandInputs>(a.change)) << r.label;
    EXPECT_NE(a.description.find("shows on"), std::string::npos) << a.description;
    // At the group's steps (sensor_delay::group_delay): the lag inputs'
    // lag<d>_ prefix. Where they differ from r's, the plan says so, and the
    // highest ranked significant sensor delay of those steps in r's group leads.
    const auto& inputs = std::get<DerivedCommandInputs>(a.change).inputs;
    ASSERT_FALSE(inputs.empty()) << a.description;
    const std::optional<trainer::DerivedInput> lag = trainer::parse_derived_input(inputs.front());
    ASSERT_TRUE(lag && lag->kind == trainer::DerivedKind::kLag) << inputs.front();
    const int d = lag->lag;
    const HypothesisResult* lead = &r;
    if (d != r.hypothesis.delay) {
      EXPECT_NE(a.description.find("the group's delay"), std::string::npos) << a.description;
      for (const auto& x : o.attribution.ranked) {
        if (!x.significant) break;
        if (x.hypothesis.kind == EffectKind::kSensorDelay && x.hypothesis.delay == d &&
            channel_group(name_of(o, x.hypothesis.target)) == channel_group(name_of(o, r.hypothesis.target))) {
          lead = &x;
          break;
        }
      }
      EXPECT_NE(lead, &r) << r.label << ": no significant delay of " << d << " steps in its group";
    }
    // Found on the first plannable significant input delay of those steps'
    // channels where there is one, else on the leading sensor delay's.
    std::vector<std::string> expected;
    for (const auto& x : o.attribution.ranked) {
      if (!x.significant) break;
      if (x.hypothesis.kind != EffectKind::kInputDelay || x.hypothesis.delay != d) continue;
      if (!why_not_fixable(o.data, o.attribution, x).empty()) continue;
      for (const auto& f : o.attribution.family_of(x)) expected.push_back(name_of(o, f.hypothesis.target));
      break;
    }
    if (expected.empty())
      for (const auto& f : o.attribution.family_of(*lead)) expected.push_back(name_of(o, f.hypothesis.target));
    EXPECT_EQ(a.found_on, expected) << r.label << ": " << a.description;
  }
  EXPECT_TRUE(seen) << "no sensor delay is significant";
}

// At most one of --fix's candidates per effect, besides a plan on its
// family alone right after the same plan extended to its group; a
// cross-talk once within a group and once between groups, a calibration
// curve once per group (two mechanisms, plan_candidates).
void expect_one_candidate_per_class(const std::vector<Augmentation>& candidates) {
  std::set<std::tuple<EffectKind, bool, std::string>> classes;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const Augmentation& a = candidates[k];
    const auto* removal = std::get_if<CrosstalkRemoval>(&a.change);
    const bool between = removal != nullptr && !removal->pairs.empty() &&
                         channel_group(removal->pairs.front().target) != channel_group(removal->pairs.front().source);
    const auto* curves = std::get_if<CalibrationCurves>(&a.change);
    const std::string curve_group =
        curves != nullptr && !curves->curves.empty() ? channel_group(curves->curves.front().channel) : "";
    EXPECT_TRUE(classes.insert({a.kind, between, curve_group}).second || is_family_alone(candidates, k))
        << "a second " << a.effect << (between ? " between groups" : "") << ": " << a.description;
  }
}

TEST(PlantEffects, LatencyIsNamedWithItsDelay) {
  // Plant: every loadcell reported 2 steps late (sensor-delay=2, the default).
  expect_loadcell_delay_wins(analyse("sensor-delay"), 2);
}

// Every loadcell reported 3 steps late, on logs of seed 871 (motions and
// noise the model never saw; a development seed of the sensor delay's rules,
// bench/residual_detection.sh). The sensor delay's regressor before stop 40,
// y_hat(t - d) - y_hat(t), also held the last d measured changes: its gain
// read 0.4-0.7, and the verdict here was "no significant effect".
// D(t - d) - D(t) on the predicted change D names it with its delay, on the
// loadcells alone, with a gain the physical domain accepts (>= 1/2,
// effects.cc).
TEST(PlantEffects, ALongerLatencyOnAnotherSeedsLogsIsNamedWithItsDelay) {
  const Outcome o = analyse("sensor-delay=3", 300, 871);
  expect_loadcell_delay_wins(o, 3);
  if (::testing::Test::HasFatalFailure()) return;
  const auto candidates = plan_candidates(o.data, o.attribution, 5);
  ASSERT_FALSE(candidates.empty());
  EXPECT_EQ(candidates.front().kind, EffectKind::kSensorDelay) << candidates.front().description;
}

TEST(PlantEffects, FrictionIsNamedOnATensionWithItsOwnMuscle) {
  // Plant: 4 N of dry friction on every tendon (friction=4, the default).
  const Outcome o = analyse("friction");
  ASSERT_TRUE(o.attribution.winner().has_value());
  const auto w = *o.attribution.winner();
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kFriction) << w.label;
  EXPECT_EQ(name_of(o, w.hypothesis.target), "f" + std::to_string(w.hypothesis.source)) << w.label;
  // The offset while moving is the friction force less what the model absorbs
  // through its inputs: measured 2.3-3.1 N of the 4 N; the bound is a factor 2.
  EXPECT_GT(std::abs(w.parameter), 2.0) << w.label;
  EXPECT_LT(std::abs(w.parameter), 8.0) << w.label;
}

TEST(PlantEffects, CrosstalkIsNamedWithAPlantPairAndGain) {
  // Plant: fingertip loadcell i adds 0.35 x its neighbour's force (crosstalk=0.35, the default).
  const Outcome o = analyse("crosstalk");
  ASSERT_TRUE(o.attribution.winner().has_value());
  const auto w = *o.attribution.winner();
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kCrosstalk) << w.label;
  // host-sim/plant/sensor_simulation.cc: thumb<-index, index<-middle, middle<-ring, ring<-little, little<-ring.
  const std::set<std::pair<std::string, std::string>> plant_pairs = {
      {"fc1", "fc0"}, {"fc2", "fc1"}, {"fc3", "fc2"}, {"fc4", "fc3"}, {"fc3", "fc4"}};
  EXPECT_TRUE(plant_pairs.count({name_of(o, w.hypothesis.source), name_of(o, w.hypothesis.target)})) << w.label;
  // Gain: 0.35 less what the model's persistence absorbs (measured 0.25-0.28); bound 0.15..0.5.
  EXPECT_GT(w.parameter, 0.15) << w.label;
  EXPECT_LT(w.parameter, 0.5) << w.label;

  // The plan removes the winner's pair and, the pair being within one group,
  // for each further target of the group its source: of its significant
  // plausible pairs with the source in the group, the one of the largest
  // held-out t (stop 71), taken in ranking order, unless it would chain
  // with a pair taken (its target a source or a target, its source a target
  // of one): with no chain, removing each pair's measured source is exact.
  // Nor a pair whose reverse is significant too (a mutual pair, as the
  // plant's fc3 <-> fc4: each reads the other, so removing one side against
  // its measured source is biased; docs/residual-experiments.md, stop 63). A target
  // whose source is left out takes no lesser pair.
  const std::vector<Augmentation> two = plan_candidates(o.data, o.attribution, 2);
  ASSERT_EQ(two.size(), 2u);
  ASSERT_TRUE(std::holds_alternative<CrosstalkRemoval>(two[0].change)) << two[0].effect;
  const auto& pairs = std::get<CrosstalkRemoval>(two[0].change).pairs;
  std::vector<std::pair<std::string, std::string>> expected = {
      {name_of(o, w.hypothesis.source), name_of(o, w.hypothesis.target)}};
  std::set<std::pair<std::string, std::string>> significant;  // (source, target)
  for (const auto& r : o.attribution.ranked) {
    if (!r.significant) break;
    if (r.hypothesis.kind == EffectKind::kCrosstalk)
      significant.insert({name_of(o, r.hypothesis.source), name_of(o, r.hypothesis.target)});
  }
  std::map<std::string, std::pair<std::string, double>> source_of;  // target -> (source, t)
  for (const auto& r : o.attribution.ranked) {
    if (!r.significant) break;
    if (r.hypothesis.kind != EffectKind::kCrosstalk) continue;
    const std::string source = name_of(o, r.hypothesis.source), target = name_of(o, r.hypothesis.target);
    if (channel_group(target) != "fc" || channel_group(source) != "fc") continue;
    if (!source_of.count(target) || r.t_stat > source_of[target].second) source_of[target] = {source, r.t_stat};
  }
  std::set<std::string> left_out;  // targets whose source forms a mutual pair
  for (const auto& r : o.attribution.ranked) {
    if (!r.significant) break;
    if (r.hypothesis.kind != EffectKind::kCrosstalk) continue;
    const std::string source = name_of(o, r.hypothesis.source), target = name_of(o, r.hypothesis.target);
    if (channel_group(target) != "fc" || channel_group(source) != "fc") continue;
    if (source_of[target].first != source) continue;  // not the target's source
    const bool chained = std::any_of(expected.begin(), expected.end(), [&](const auto& x) {
      return x.second == target || x.first == target || x.second == source;
    });
    if (chained) continue;
    if (significant.count({target, source})) {  // mutual: the target takes no pair
      left_out.insert(target);
      continue;
    }
    expected.push_back({source, target});
  }
  const std::size_t mutual_left_out = left_out.size();
  std::vector<std::pair<std::string, std::string>> planned;
  for (const auto& x : pairs) planned.push_back({x.source, x.target});
  EXPECT_EQ(planned, expected);
  // On these logs the plant's chain gives more than one pair: the extension is exercised;
  // every pair taken is one of the plant's.
  EXPECT_GT(pairs.size(), 1u);
  for (const auto& x : pairs) EXPECT_TRUE(plant_pairs.count({x.source, x.target})) << x.source << " -> " << x.target;
  ASSERT_EQ(two[0].channels.size(), pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) EXPECT_EQ(two[0].channels[k], pairs[k].target);
  EXPECT_EQ(two[0].found_on, two[0].channels);
  EXPECT_EQ(two[0].extended_channels, std::vector<std::string>(two[0].channels.begin() + 1, two[0].channels.end()));
  for (std::size_t k = 1; k < pairs.size(); ++k)
    EXPECT_EQ(significant.count({pairs[k].target, pairs[k].source}), 0u) << pairs[k].source << " -> " << pairs[k].target;
  std::printf("cross-talk plan: %s (%zu targets of a mutual pair left out)\n", two[0].description.c_str(),
              mutual_left_out);
  // A model that already removes fc1 -> fc0 (an earlier round's pair): the
  // further pairs chain with it no more (fc1 -> fc0 was one of them above).
  ResidualData earlier = o.data;
  earlier.crosstalk = {{"fc0", "fc1", 0.3}};
  const std::vector<Augmentation> later = plan_candidates(earlier, o.attribution, 1);
  ASSERT_EQ(later.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<CrosstalkRemoval>(later[0].change)) << later[0].effect;
  const auto& later_pairs = std::get<CrosstalkRemoval>(later[0].change).pairs;
  EXPECT_LT(later_pairs.size(), pairs.size());
  for (std::size_t k = 1; k < later_pairs.size(); ++k)
    EXPECT_FALSE(forms_chain(later_pairs[k], earlier.crosstalk)) << later_pairs[k].source << " -> " << later_pairs[k].target;
  // The winner's pair alone follows.
  ASSERT_TRUE(std::holds_alternative<CrosstalkRemoval>(two[1].change)) << two[1].effect;
  EXPECT_FALSE(two[1].group_extension);
  ASSERT_EQ(std::get<CrosstalkRemoval>(two[1].change).pairs.size(), 1u);
  EXPECT_EQ(std::get<CrosstalkRemoval>(two[1].change).pairs.front(), pairs.front());
}

TEST(PlantEffects, TensionLeakIsNamedAcrossGroupsWithItsGain) {
  // Plant: the palm loadcell fc6 adds 0.2 x tendon 5's tension (tension-leak=0.2), a cross-talk between
  // groups of one unit (N): the default sources hold the pair.
  Outcome o;
  o.data = compute_residuals(build_model(), plant_logs("tension-leak=0.2"), "auto");
  o.attribution = attribute(o.data, enumerate_hypotheses(o.data, {}), {});
  ASSERT_TRUE(o.attribution.winner().has_value());
  const auto w = *o.attribution.winner();
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kCrosstalk) << w.label;
  EXPECT_EQ(name_of(o, w.hypothesis.source), "f5") << w.label;
  EXPECT_EQ(name_of(o, w.hypothesis.target), "fc6") << w.label;
  // The first coefficient is the gain itself (y_s(t) and y_s(t-1) are both regressors, so what the
  // network carries over of the pick-up is not subtracted from it); bound: within 0.5x..1.5x.
  EXPECT_GT(w.parameter, 0.1) << w.label;
  EXPECT_LT(w.parameter, 0.3) << w.label;
  // A cross-talk between groups is one path: its pair alone is removed.
  const std::vector<Augmentation> plan = plan_candidates(o.data, o.attribution, 1);
  ASSERT_EQ(plan.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<CrosstalkRemoval>(plan.front().change)) << plan.front().effect;
  ASSERT_EQ(std::get<CrosstalkRemoval>(plan.front().change).pairs.size(), 1u);
  EXPECT_EQ(plan.front().channels, std::vector<std::string>{"fc6"});
  EXPECT_TRUE(plan.front().extended_channels.empty());
  // Only because tensions and loadcells share a unit (N): the target's group alone does not hold f5.
  LibraryOptions same_group;
  same_group.crosstalk_sources = CrosstalkSources::kSameGroup;
  for (const auto& h : enumerate_hypotheses(o.data, same_group))
    EXPECT_FALSE(h.kind == EffectKind::kCrosstalk && name_of(o, h.target) == "fc6" && name_of(o, h.source) == "f5");
}

// The winner is a load drift on a loadcell with a rate within 0.2x..1.5x
// `plant_rate` (the 1-step residual keeps what the model does not carry over).
void expect_load_drift_on_a_loadcell(const Outcome& o, double plant_rate) {
  ASSERT_TRUE(o.attribution.winner().has_value());
  const auto w = *o.attribution.winner();
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kDriftLoad) << w.label;
  EXPECT_EQ(channel_group(name_of(o, w.hypothesis.target)), "fc") << w.label;
  EXPECT_GT(w.parameter, 0.2 * plant_rate) << w.label;
  EXPECT_LT(w.parameter, 1.5 * plant_rate) << w.label;
}

TEST(PlantEffects, DriftIsNamedAtFiveTimesTheDefaultRate) {
  // Plant: loadcell bias growing 0.02 N per N s of load (5x the default 0.004, which leaves
  // no detectable 1-step residual: docs/residual.md) plus a 0.01 N/sqrt(step) random walk.
  // The 1-step residual keeps only what the model does not carry over from the
  // biased x_t (measured rate 0.0084 of 0.02); bound 0.2x..1.5x the plant's rate.
  expect_load_drift_on_a_loadcell(analyse("drift=0.02"), 0.02);
}

TEST(PlantEffects, DefaultDriftIsNamedOnLongLogsAndCleanLongLogsGiveNothing) {
  // 1000-step logs of the same grasps. Clean: nothing (with the plausibility
  // domains; before them, a negative cross-talk fc5 -> fc6 passed the floor).
  const Outcome clean = analyse("", 1000);
  EXPECT_FALSE(clean.attribution.winner().has_value()) << clean.attribution.ranked.front().label;
  // Plant default drift: 0.004 N per N s of load plus a 0.01 N/sqrt(step) walk.
  // Rate (measured 0.0033 on fc2): within 0.2x..1.5x the plant's, less what
  // persistence carries over.
  expect_load_drift_on_a_loadcell(analyse("drift", 1000), 0.004);
}

TEST(PlantEffects, SaturationIsNamedWithItsRailAtTwoNewtons) {
  // Plant: loadcells clipped at 2 N (the default 3 N clips too few samples of these grasps:
  // docs/residual.md). The rail estimate is the largest measured value: the rail plus
  // sensor noise (20 mN sd) and quantisation, so within 0.1 N.
  const Outcome o = analyse("saturation=2");
  ASSERT_TRUE(o.attribution.winner().has_value());
  const auto w = *o.attribution.winner();
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kSaturation) << w.label;
  EXPECT_EQ(w.hypothesis.side, +1) << w.label;
  EXPECT_EQ(channel_group(name_of(o, w.hypothesis.target)), "fc") << w.label;
  EXPECT_NEAR(w.hypothesis.rail, 2.0, 0.1) << w.label;

  // The plan clips the winner's family and every other loadcell whose upper
  // rail passes the test without the floors (Holm p < alpha, a positive
  // gain), each at its own rail: the plant clips every loadcell at 2 N, and
  // a rail belongs to the acquisition chain, as a sensor delay does.
  const std::vector<Augmentation> plan = plan_candidates(o.data, o.attribution, 1);
  ASSERT_EQ(plan.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<OutputClips>(plan.front().change)) << plan.front().effect;
  const auto& clips = std::get<OutputClips>(plan.front().change).clips;
  std::set<std::string> clipped, family, passing;
  for (const auto& clip : clips) {
    clipped.insert(clip.channel);
    EXPECT_EQ(clip.side, +1) << clip.channel;
    EXPECT_NEAR(clip.rail, 2.0, 0.1) << clip.channel;  // the rail plus noise and quantisation, as above
  }
  for (const auto& r : o.attribution.family_of(w)) family.insert(name_of(o, r.hypothesis.target));
  for (const auto& r : o.attribution.ranked)
    if (r.hypothesis.kind == EffectKind::kSaturation && r.hypothesis.side > 0 && r.testable && r.plausible &&
        r.p_adjusted < o.attribution.options.alpha && channel_group(name_of(o, r.hypothesis.target)) == "fc")
      passing.insert(name_of(o, r.hypothesis.target));
  // Exactly those: nothing of another group, side or test result.
  std::set<std::string> expected = family;
  expected.insert(passing.begin(), passing.end());
  EXPECT_EQ(clipped, expected);
  EXPECT_EQ(clips.size(), clipped.size());  // one clip per channel
  EXPECT_EQ(plan.front().found_on, plan.front().channels);
  std::printf("rails clipped: %zu (family %zu, passing the test in fc %zu): %s\n", clipped.size(), family.size(),
              passing.size(), plan.front().description.c_str());
  // On these logs the test finds the rail on loadcells outside the family: the extension is exercised.
  EXPECT_GT(clipped.size(), family.size());
  std::set<std::string> added(plan.front().extended_channels.begin(), plan.front().extended_channels.end()), outside_family;
  std::set_difference(expected.begin(), expected.end(), family.begin(), family.end(),
                      std::inserter(outside_family, outside_family.end()));
  EXPECT_EQ(added, outside_family);

  // With room for two candidates the same rail follows on the family alone,
  // which the selection on the training rows tries when the rail on the
  // group does not gain significantly (a rail of one sensor would leave
  // traces on the others through the network).
  const std::vector<Augmentation> two = plan_candidates(o.data, o.attribution, 2);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].description, plan.front().description);
  ASSERT_TRUE(std::holds_alternative<OutputClips>(two[1].change)) << two[1].effect;
  EXPECT_FALSE(two[1].group_extension);
  EXPECT_TRUE(two[1].extended_channels.empty());
  std::set<std::string> alone;
  for (const auto& clip : std::get<OutputClips>(two[1].change).clips) alone.insert(clip.channel);
  EXPECT_EQ(alone, family);
}

// The plant logs no aux_* channel, so this one is synthetic on top of clean
// plant logs: a slow "temperature" column, which on the effect logs also adds
// 0.5 N per unit to loadcell fc3 (as a temperature-dependent offset would).
// (On a tension, whose standardisation std is 31 N, an offset must be ~9 N per
// unit to pass the floor of 0.05 standardised units; docs/residual.md.)
std::vector<LogInput> with_aux(bool affects_fc3) {
  std::vector<LogInput> logs = plant_logs("");
  int l = 0;
  for (auto& in : logs) {
    auto& table = in.table;
    const std::size_t fc3 = *table.column_index("fc3"), cols = table.columns.size();
    std::vector<double> values;
    for (std::size_t t = 0; t < table.rows(); ++t) {
      const double temp = std::sin(0.04 * static_cast<double>(t) + l) + 0.5 * std::sin(0.13 * static_cast<double>(t));
      for (std::size_t c = 0; c < cols; ++c) values.push_back(table.at(t, c) + (affects_fc3 && c == fc3 ? 0.5 * temp : 0.0));
      values.push_back(temp);
    }
    table.columns.push_back("aux_temp");
    table.values = std::move(values);
    ++l;
  }
  return logs;
}

TEST(PlantEffects, UnusedAuxChannelIsNamedAndAnUnrelatedOneIsNot) {
  const ResidualData clean = compute_residuals(build_model(), with_aux(false), "auto");
  const Attribution none = attribute(clean, enumerate_hypotheses(clean, {}), {});
  EXPECT_FALSE(none.winner().has_value()) << none.ranked.front().label;

  const ResidualData data = compute_residuals(build_model(), with_aux(true), "auto");
  const Attribution a = attribute(data, enumerate_hypotheses(data, {}), {});
  ASSERT_TRUE(a.winner().has_value());
  const auto w = *a.winner();
  std::printf("aux: %s share %.3f std %.4f p(Holm) %.2g\n", w.label.c_str(), w.explained, w.explained_std, w.p_adjusted);
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kAuxChannel) << w.label;
  EXPECT_EQ(data.y_names[static_cast<std::size_t>(w.hypothesis.target)], "fc3") << w.label;
  EXPECT_GT(w.parameter, 0.1) << w.label;  // 0.5 less what the model carries over from x_t
  EXPECT_LT(w.parameter, 0.75) << w.label;
}

}  // namespace
}  // namespace hadynet::test

namespace hadynet::test {
namespace {

using trainer::residual::ResidualLog;

// Measured on these logs: 2 of 4 replaced (trained / adapted held-out loss
// per channel, geometric mean: Ball/i2 1.90, Cylinder/i0 2.45). Kept:
// Cylinder/i1 (0.99: the trained PB fits this zeroing as well) and Gripper/i0
// (0.42: no PB fits it, the adapted one neither; mean losses 6.6 vs 6.2). The
// mean-loss rule before stop 44 replaced the same two. The bar is the
// measured count: fewer means the check lost a state it finds today.
constexpr int kRezeroedReplacedAtLeast = 2;

// --pb auto checks a state's trained PB on the state's held-out rows. A hand
// re-zeroed since training that keeps its state names (logs recorded under
// zeroings the model never saw, init ids 300..303, relabelled with the
// trained names; issue 12 saw the 1-step fit of f0..f2 fall below -180 %
// with the stored PBs): the trained PBs must be replaced by adapted ones where
// they predict worse by more than the margin, and the summary must say why.
TEST(PbAuto, TrainedPbOfAnotherZeroingIsReplaced) {
  const trainer::residual::ResidualData data =
      trainer::residual::compute_residuals(build_model(), rezeroed_plant_logs(300), "auto");
  int replaced = 0;
  for (const auto& log : data.logs) {
    std::printf("%s: %s\n", log.seq.file.c_str(), log.pb_source.c_str());
    ASSERT_TRUE(log.pb_check.checked) << log.seq.file;
    if (log.pb_origin == ResidualLog::PbOrigin::kAdaptedOverTrained) ++replaced;
    // The rule the origin follows, whatever the losses.
    EXPECT_EQ(log.pb_origin == ResidualLog::PbOrigin::kAdaptedOverTrained,
              log.pb_check.channel_ratio > trainer::residual::kStoredPbMargin);
  }
  std::printf("trained PB replaced for %d of %zu re-zeroed logs\n", replaced, data.logs.size());
  EXPECT_GE(replaced, kRezeroedReplacedAtLeast);
  EXPECT_NE(trainer::residual::pb_summary(data, "auto").find("predicted their held-out rows worse"), std::string::npos);
}

// The training seed's own zeroings: the trained PBs were fit to exactly these
// states, so replacing one would be a false alarm of the check. Measured: the
// trained PB's held-out loss is below the adapted one's on all four (0.012 vs
// 0.022, 0.069 vs 0.085, 0.020 vs 0.40, 0.010 vs 0.037): kept, every one.
TEST(PbAuto, TrainingZeroingsKeepTheirTrainedPb) {
  const trainer::residual::ResidualData data = trainer::residual::compute_residuals(build_model(), plant_logs("", 300, 1), "auto");
  int kept = 0;
  for (const auto& log : data.logs) {
    std::printf("%s: %s\n", log.seq.file.c_str(), log.pb_source.c_str());
    if (log.pb_origin == ResidualLog::PbOrigin::kTrained) ++kept;
  }
  std::printf("trained PB kept for %d of %zu logs of the training zeroings\n", kept, data.logs.size());
  EXPECT_EQ(kept, static_cast<int>(data.logs.size()));
  EXPECT_EQ(trainer::residual::pb_summary(data, "auto").find("worse"), std::string::npos);
}

// A strong effect on one channel is not a new state. A tendon's tension
// leaking into a palm loadcell (tension-leak=0.2, seed 1202: development
// data of the check) makes the trained PB predict fc6 much worse, and the
// mean held-out loss with it (trained/adapted 1.21, 1.12, 2.99, 1.26 for the
// four grasps: the mean-loss rule replaced three PBs and the adapted PBs
// absorbed part of the leak). Per channel the trained PB still predicts a
// typical channel better (geometric mean 0.15-0.40), so every one is kept;
// bound: all four, since the largest ratio is a third of the margin. The
// logs must still be ones the mean loss misreads (at least one mean-loss
// ratio above the margin: 2.99 measured), or the test would prove nothing.
TEST(PbAuto, AStrongEffectOnOneChannelKeepsTheTrainedPb) {
  namespace rs = trainer::residual;
  const rs::ResidualData data = rs::compute_residuals(build_model(), plant_logs("tension-leak=0.2", 300, 1202), "auto");
  ASSERT_EQ(data.logs.size(), 4u);
  int kept = 0, mean_loss_worse = 0;
  for (const auto& log : data.logs) {
    std::printf("%s: %s\n", log.seq.file.c_str(), log.pb_source.c_str());
    ASSERT_TRUE(log.pb_check.checked) << log.seq.file;
    if (log.pb_origin == ResidualLog::PbOrigin::kTrained) ++kept;
    if (log.pb_check.stored_loss > rs::kStoredPbMargin * log.pb_check.adapted_loss) ++mean_loss_worse;
    EXPECT_EQ(log.pb_origin == ResidualLog::PbOrigin::kAdaptedOverTrained,
              log.pb_check.channel_ratio > rs::kStoredPbMargin);
  }
  std::printf("trained PB kept for %d of %zu tension-leak logs (mean loss worse by the margin: %d)\n", kept,
              data.logs.size(), mean_loss_worse);
  EXPECT_GE(mean_loss_worse, 1);
  EXPECT_EQ(kept, static_cast<int>(data.logs.size()));
}

}  // namespace
}  // namespace hadynet::test

namespace hadynet::test {
namespace {

// The plant's loadcells clip at their rated floor, 0 N (sensor realism,
// on in "clean" logs too). On clean logs of fresh seeds the screen's winner
// is often a "lower rail at 0" of a contact-free loadcell, and --fix confirms
// it (docs/residual.md: 7 of 20 clean sets of seeds 121-140). Given the
// datasheet's range (--rated-range fc=0..50), the predictions are clipped
// there as known and no rail at 0 is left to find. Seed 64 (development
// data of the false-positive table): the rail was its confirmed effect.
TEST(RatedRange, AKnownRatedFloorIsNotAnEffect) {
  namespace rs = trainer::residual;
  const auto logs = plant_logs("", 300, 64);
  const auto rail_at_zero = [](const rs::HypothesisResult& r) {
    return r.significant && r.effect == "saturation" && r.hypothesis.side < 0 && std::abs(r.hypothesis.rail) < 0.05;
  };
  rs::AnalysisOptions o;
  const rs::Analysis before = rs::analyse(build_model(), logs, o);
  const auto n_before = std::count_if(before.attribution.ranked.begin(), before.attribution.ranked.end(), rail_at_zero);
  std::printf("without --rated-range: %s (%ld significant rails at 0)\n", before.verdict.c_str(), static_cast<long>(n_before));
  ASSERT_GT(n_before, 0) << "the seed no longer shows the floor: " << before.verdict;
  const auto model = rs::with_rated_ranges(build_model(), {rs::parse_rated_range("fc=0..50")});
  const rs::Analysis after = rs::analyse(model, logs, o);
  const auto n_after = std::count_if(after.attribution.ranked.begin(), after.attribution.ranked.end(), rail_at_zero);
  std::printf("with fc=0..50: %s (%ld significant rails at 0)\n", after.verdict.c_str(), static_cast<long>(n_after));
  EXPECT_EQ(n_after, 0);
}


// The calibrated null (docs/residual.md, "A calibrated null"): clean logs of
// the same four grasps recorded with seed 12 (development data) are the
// null; the floors are relative to the model's residual there.
const std::vector<trainer::residual::LogInput>& null_logs() {
  static const auto logs = plant_logs("", 300, 12);
  return logs;
}

// Plant: the servos act on every command 2 steps after it is sent
// (input-delay=2, the default). The screen names the delay with its steps on
// channels of more than one group (the commands drive lengths, tensions and
// loadcells), so --fix can add it: the commands 2 steps earlier as inputs,
// one per command. Below the winner: on these logs the model's fingertip
// misfit (a cross-talk pair) ranks first, so --fix reaches it among its first
// three candidates (docs/residual.md, "Input dead time").
TEST(PlantEffects, InputDelayIsNamedOnSeveralGroupsAndAddedAsLaggedCommands) {
  const Outcome o = analyse("input-delay");
  const auto it = std::find_if(o.attribution.ranked.begin(), o.attribution.ranked.end(), [](const auto& r) {
    return r.significant && r.hypothesis.kind == EffectKind::kInputDelay;
  });
  ASSERT_NE(it, o.attribution.ranked.end()) << "no input delay significant";
  EXPECT_EQ(it->hypothesis.delay, 2) << it->label;
  std::set<std::string> groups;
  for (const auto& r : o.attribution.family_of(*it)) groups.insert(channel_group(name_of(o, r.hypothesis.target)));
  EXPECT_GE(groups.size(), 2u) << it->label;
  EXPECT_EQ(why_not_fixable(o.data, o.attribution, *it), "");
  const auto candidates = plan_candidates(o.data, o.attribution, 3);
  const auto planned = std::find_if(candidates.begin(), candidates.end(),
                                    [](const Augmentation& a) { return a.kind == EffectKind::kInputDelay; });
  ASSERT_NE(planned, candidates.end()) << "input delay not among the first three candidates";
  const auto& inputs = std::get<DerivedCommandInputs>(planned->change).inputs;
  ASSERT_EQ(inputs.size(), 8u);
  for (std::size_t m = 0; m < inputs.size(); ++m) EXPECT_EQ(inputs[m], "lag2_u" + std::to_string(m));
  // Declined, with a reason: a model that has the lagged commands already
  // (an earlier round added them), and a delay longer than a lag input states.
  ResidualData fixed = o.data;
  fixed.u_names.insert(fixed.u_names.end(), inputs.begin(), inputs.end());
  EXPECT_NE(why_not_fixable(fixed, o.attribution, *it).find("already has"), std::string::npos);
  HypothesisResult longer = *it;
  longer.hypothesis.delay = trainer::kMaxCommandLag + 1;
  EXPECT_NE(why_not_fixable(o.data, o.attribution, longer).find("longer than"), std::string::npos);
}

// A sensor delay of one group leaves nearly the residual of an input delay
// on the channels the commands drive directly: an input delay seen on that
// group only, beside a significant sensor delay there, is not added (the
// sensor delay is, test above).
TEST(PlantEffects, AnInputDelaySeenOnlyBesideASensorDelayIsNotAdded) {
  const Outcome o = analyse("sensor-delay");
  bool declined = false;
  for (const auto& r : o.attribution.ranked) {
    if (!r.significant || r.hypothesis.kind != EffectKind::kInputDelay) continue;
    std::set<std::string> groups;
    for (const auto& f : o.attribution.family_of(r)) groups.insert(channel_group(name_of(o, f.hypothesis.target)));
    if (groups != std::set<std::string>{"fc"}) continue;
    EXPECT_NE(why_not_fixable(o.data, o.attribution, r), "") << r.label;
    declined = true;
  }
  EXPECT_TRUE(declined) << "no input delay seen on the loadcells alone";
  for (const auto& a : plan_candidates(o.data, o.attribution, 3)) EXPECT_NE(a.kind, EffectKind::kInputDelay) << a.description;
}

// Commands acting 2 steps late delay every channel they drive, and the
// sensor delay's regressor follows the model, so sensor delays are
// significant on several groups (lengths, tensions, loadcells). No sensor
// delay may then be added: --fix's candidates hold the input delay and no
// sensor delay (with the new regressor and without this rule, a time
// alignment of several groups was confirmed on such logs: development seeds
// 871-875).
TEST(PlantEffects, CommandsActingLateAreNotAlignedAsASensorDelay) {
  const Outcome o = analyse("input-delay");
  std::set<std::string> delayed_groups;
  for (const auto& r : o.attribution.ranked)
    if (r.significant && r.hypothesis.kind == EffectKind::kSensorDelay)
      delayed_groups.insert(channel_group(name_of(o, r.hypothesis.target)));
  EXPECT_GE(delayed_groups.size(), 2u);
  expect_every_sensor_delay_is_a_dead_time(o);
  const auto candidates = plan_candidates(o.data, o.attribution, 5);
  expect_one_candidate_per_class(candidates);
  EXPECT_TRUE(std::any_of(candidates.begin(), candidates.end(),
                          [](const Augmentation& a) { return a.kind == EffectKind::kInputDelay; }));
  for (const auto& a : candidates) EXPECT_NE(a.kind, EffectKind::kSensorDelay) << a.description;
}

// Seed 64's confirmed false positive without rated ranges was a contact-free
// loadcell's real floor at 0 N (RatedRange above): the clean null shows the
// same floor, so with it nothing is significant, with no rated range given.
TEST(CalibratedNull, ASensorsRealFloorIsTheNullNotAnEffect) {
  namespace rs = trainer::residual;
  const auto logs = plant_logs("", 300, 64);
  const rs::Analysis without = rs::analyse(build_model(), logs, {});
  ASSERT_TRUE(without.attribution.winner().has_value()) << "seed 64 no longer shows its floor";
  const rs::Analysis with = rs::analyse(build_model(), logs, {}, null_logs());
  ASSERT_TRUE(with.attribution.null.has_value());
  std::printf("seed 64: without a null: %s; with: %s\n", without.verdict.c_str(), with.verdict.c_str());
  EXPECT_FALSE(with.attribution.winner().has_value()) << with.verdict;
}

// An effect beyond the null is still named: friction of 4 N on the tendons
// (the effect logs of the other tests), on a tension with its own muscle.
TEST(CalibratedNull, FrictionBeyondTheNullIsNamedOnATension) {
  namespace rs = trainer::residual;
  const rs::Analysis a = rs::analyse(build_model(), plant_logs("friction=4"), {}, null_logs());
  std::printf("friction=4 with the null: %s\n", a.verdict.c_str());
  ASSERT_TRUE(a.attribution.winner().has_value());
  const auto w = *a.attribution.winner();
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kFriction);
  EXPECT_EQ(channel_group(a.data.y_names[static_cast<std::size_t>(w.hypothesis.target)]), "f");
  EXPECT_GE(w.excess_share, kDefaultMinExcessNull);
}

TEST(PlantEffects, ACalibrationCurveIsNamedOnALoadcellAndItsGroupWithANull) {
  // Plant: every loadcell reads 50 N (F / 50 N)^0.85 of its force F
  // (sensor-curve, the default: +80 % at 1 N, +27 % at 10 N). Curves are
  // tested only against a null (effects.h, LibraryOptions::sensor_curves):
  // without one the library has no curve hypothesis. The null: the model's
  // stored held-out logs, as `hadynet residual` by default.
  namespace rs = trainer::residual;
  const auto logs = plant_logs("sensor-curve");
  const rs::Analysis without = rs::analyse(build_model(), logs, {});
  for (const auto& r : without.attribution.ranked) EXPECT_NE(r.hypothesis.kind, EffectKind::kSensorCurve);
  EXPECT_NE(rs::floors_summary(without).find("calibration curves are not tested"), std::string::npos);
  rs::AnalysisOptions options;
  options.reference_pb_choice = "state";
  const rs::Analysis o = rs::analyse(build_model(), logs, options, stored_null());
  std::printf("sensor-curve with the null: %s\n", o.verdict.c_str());
  ASSERT_TRUE(o.attribution.winner().has_value());
  const auto w = *o.attribution.winner();
  EXPECT_EQ(w.hypothesis.kind, EffectKind::kSensorCurve) << w.label;
  EXPECT_EQ(channel_group(o.data.y_names[static_cast<std::size_t>(w.hypothesis.target)]), "fc") << w.label;
  // --fix's plan: a curve on the winner and the loadcells where the curve
  // tests significant (the group), never on another group's channel.
  const auto candidates = plan_candidates(o.data, o.attribution, 1);
  ASSERT_EQ(candidates.size(), 1u);
  const auto& curves = std::get<CalibrationCurves>(candidates.front().change).curves;
  EXPECT_GE(curves.size(), 5u);
  for (const auto& c : curves) {
    EXPECT_EQ(channel_group(c.channel), "fc") << c.channel;
    EXPECT_EQ(c.level, c.reading) << c.channel;  // the identity, which refine() fits
  }
}

// `hadynet residual LOGS --rated-range fc=0..50 --rated-range f=0..200` (the
// benchmarks' analysis): the plant's datasheet ranges, and the model's stored
// held-out logs as the null, with their trained PBs.
Outcome analyse_with_the_stored_null(const std::string& effect, std::uint64_t seed) {
  namespace rs = trainer::residual;
  static const auto model = rs::with_rated_ranges(
      build_model(), {rs::parse_rated_range("fc=0..50"), rs::parse_rated_range("f=0..200")});
  trainer::SensorModel reference_sensor;  // the stored logs: the training logs, rated ranges only
  reference_sensor.clips = model.sensor.clips;
  rs::AnalysisOptions options;
  options.reference_pb_choice = "state";
  options.reference_sensor = &reference_sensor;
  rs::Analysis a = rs::analyse(model, plant_logs(effect, 300, seed), options, stored_null());
  std::printf("%s, seed %llu, with the stored null: %s\n", effect.c_str(), static_cast<unsigned long long>(seed),
              a.verdict.c_str());
  return {std::move(a.data), std::move(a.attribution)};
}

// Commands acting 1 step late, on logs of seed 874 (a development seed of
// the rule, bench/residual_detection.sh), analysed as the benchmarks do:
// sensor delays pass the floors on the loadcells alone, and no input delay
// does, so before stop 41 --fix time-aligned the loadcells (and confirmed
// it). The same 1-step delay shows, below the floors, on the tendon lengths,
// tensions and joint angles with median gains of 0.6-0.8 (a loadcell delay
// leaves them 0.1-0.4), so the sensor delay is planned as the commands' dead
// time.
TEST(PlantEffects, ADeadTimeSeenOnTheLoadcellsAloneIsNotAlignedAsALoadcellDelay) {
  const Outcome o = analyse_with_the_stored_null("input-delay=1", 874);
  // The premise: sensor delays significant on the loadcells alone, no input delay.
  for (const auto& r : o.attribution.ranked) {
    if (!r.significant) break;
    EXPECT_NE(r.hypothesis.kind, EffectKind::kInputDelay) << r.label;
    if (r.hypothesis.kind == EffectKind::kSensorDelay) {
      EXPECT_EQ(channel_group(name_of(o, r.hypothesis.target)), "fc") << r.label;
    }
  }
  expect_every_sensor_delay_is_a_dead_time(o);
  const auto candidates = plan_candidates(o.data, o.attribution, 5);
  expect_one_candidate_per_class(candidates);
  ASSERT_FALSE(candidates.empty());
  for (const auto& a : candidates) EXPECT_NE(a.kind, EffectKind::kSensorDelay) << a.description;
  EXPECT_EQ(candidates.front().kind, EffectKind::kInputDelay) << candidates.front().description;
  const auto& inputs = std::get<DerivedCommandInputs>(candidates.front().change).inputs;
  ASSERT_FALSE(inputs.empty());
  for (const auto& name : inputs) EXPECT_EQ(name.rfind("lag1_", 0), 0u) << name;
}

// Commands acting 1 step late on logs of seed 990 (development data of the
// rule's second step, bench/residual_detection.sh): an input delay ranks
// above a sensor delay that shows on other groups, whose plan is the same
// dead time. Before the candidates were told apart by the effect planned,
// --fix tried it twice.
TEST(PlantEffects, ADeadTimeIsOneCandidateWhateverLedToIt) {
  const Outcome o = analyse_with_the_stored_null("input-delay=1", 990);
  const auto candidates = plan_candidates(o.data, o.attribution, 5);
  ASSERT_FALSE(candidates.empty());
  EXPECT_EQ(candidates.front().kind, EffectKind::kInputDelay) << candidates.front().description;
  expect_one_candidate_per_class(candidates);
}

// The mirror: loadcells reported 1 step late, on logs of seed 874, are still
// time-aligned (the other groups' 1-step delays read median gains of 0.16-0.24).
TEST(PlantEffects, ALoadcellDelayOfOneStepIsStillAlignedBesideTheRule) {
  const Outcome o = analyse_with_the_stored_null("sensor-delay=1", 874);
  const auto candidates = plan_candidates(o.data, o.attribution, 5);
  ASSERT_FALSE(candidates.empty());
  EXPECT_EQ(candidates.front().kind, EffectKind::kSensorDelay) << candidates.front().description;
  ASSERT_TRUE(std::holds_alternative<TimeAlignment>(candidates.front().change));
  EXPECT_EQ(std::get<TimeAlignment>(candidates.front().change).delay, 1);
  for (const auto& c : candidates.front().channels) EXPECT_EQ(channel_group(c), "fc") << c;
}

}  // namespace
}  // namespace hadynet::test
