// The effect library of the residual loop (docs/residual.md): each effect is a
// named hypothesis about what the model lacks, with
//   (a) a feature test: regressors built from the logs, the model's 1-step
//       predictions and the auxiliary channels, which should explain the
//       1-step residual of one target channel if the effect is present, and
//   (b) a model augmentation (added by `hadynet residual --fix`, augment.h).
// A hypothesis is one effect with its parameters (target channel, source,
// delay, rail). Nothing here knows the hand: channels come by index into the
// ResidualData's names.
//
// Everything about one effect is one row of the table in effects.cc
// (EffectInfo below): its texts, which hypotheses it enumerates, its feature
// test, its parameter and physical domain, its description, and the plan of
// its augmentation; how the augmentation changes a model is its alternative
// of Augmentation::change (augment.h), defined in the same section of
// effects.cc. effects.cc says at the table how to add an effect.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "trainer/residual/residuals.h"

namespace hadynet::trainer::residual {

// One per row of the effect table (effects.cc), in its order.
enum class EffectKind {
  kSensorDelay,  // the target is reported `delay` steps late
  kInputDelay,   // the commands act `delay` steps later than the model assumes
  kFriction,     // dry friction / hysteresis driven by the motion of muscle `source` (u channel)
  kDriftLoad,    // a sensor bias growing with the target's accumulated value (load)
  kDriftTime,    // a sensor bias growing with time
  kSaturation,   // the measured target is clipped at a rail (`side` +1 upper, -1 lower)
  kSensorCurve,  // the target reports a static monotone curve of its own level
  kCrosstalk,    // the target picks up a fraction of channel `source` (y channel)
  kAuxChannel,   // an unused logged channel (aux `source`) explains the target
};

struct Hypothesis {
  EffectKind kind = EffectKind::kSensorDelay;
  int target = 0;      // y channel whose residual is explained
  int source = -1;     // u channel (friction), y channel (crosstalk), aux channel (aux); else -1
  int delay = 0;       // steps (delays); 0 for the other effects (a family shares it: attribution.h)
  int side = 0;        // saturation: +1 upper rail, -1 lower rail; 0 for the other effects
  double rail = 0;     // saturation: the rail, target units
  // friction: the source is an absolute command, so its motion is its change
  // (regressors and inputs of u's change: derived_inputs.h dsign_/dhyst_)
  bool of_change = false;
  // sensor-curve: the midpoint and half the width of the 5-95 % range of
  // the target's values over the logs (target units, the model's frame); 0
  // for the other effects.
  double centre = 0, half_range = 0;
};

// Regressors of a hypothesis for one log, aligned with the log's residual
// columns (row t = j + 2); rows before `first_valid` are undefined (delays).
struct Features {
  Eigen::MatrixXd z;  // n x k
  int first_valid = 0;
};

// Cross-talk sources of a target channel c.
enum class CrosstalkSources {
  // The other channels of c's group, and the channels of any other group
  // measured in c's unit (ResidualData::y_units; a channel without a
  // declared unit only within its group): a sensor may pick up a channel of
  // another group (a tendon's tension leaking into a palm loadcell), and a
  // pick-up fraction (the gain's physical domain, 0..1) means something
  // only between channels of one unit.
  kSameUnit,
  kSameGroup,  // the other channels of c's group only
  kAll,        // every other y channel
};

struct LibraryOptions {
  int max_delay = 5;                // delays 1..max_delay steps
  // The absolute command groups (ResidualData::u_absolute); nullopt: as the
  // logs' `absolute_groups` metadata says.
  std::optional<std::vector<std::string>> absolute_groups;
  // Which y channels may be a cross-talk source of a target.
  CrosstalkSources crosstalk_sources = CrosstalkSources::kSameUnit;
  // A rail is where a signal sits, not merely its extreme: a side of a
  // channel is a saturation candidate only when at least min_rail_share of
  // its rows (and at least 5) lie within rail_band of its range from the
  // extreme: a saturated sensor sits there with its noise on top. (Clean
  // plant logs, seed 31: a loadcell's maximum of 0.061 N, 7 of 1 200 rows in
  // that band, was clipped and "confirmed"; real rails: the plant's loadcells
  // clipped at 2 N put 3-16 % of their rows in it (noise sd 20 mN), its rated
  // floor at 0 N holds 50-85 % of a contact-free loadcell's rows, the
  // Cascaded Tanks' 10 V about 5 %.)
  double min_rail_share = 0.02;
  double rail_band = 0.05;
  // Whether the calibration curve (sensor-curve) is tested. Its regressors
  // are the channel's own level now and one row earlier, which explain part
  // of any model's misfit of that channel (clean mass-spring logs: a curve
  // on three channels past the absolute floors, outranking a real sensor
  // delay); only a null, the model's residual on clean logs, tells an effect
  // from that. analyse() sets it when it has reference logs.
  bool sensor_curves = false;
};

// What Hypothesis::source indexes for an effect.
enum class SourceKind {
  kNone,      // no source (source = -1)
  kCommand,   // a u channel (ResidualData::u_names)
  kObserved,  // another y channel (y_names)
  kAux,       // an aux_* channel (aux_names)
};

struct Attribution;       // attribution.h
struct HypothesisResult;  // attribution.h
struct Augmentation;      // augment.h

// One effect of the library: everything about it (one row of the table in
// effects.cc). The functions are given hypotheses of this effect only.
struct EffectInfo {
  EffectKind kind;
  const char* name;          // used in the CLI, the JSON and the report
  const char* feature;       // the regressors of the feature test
  const char* parameter;     // what the fitted parameter means
  const char* augmentation;  // the model augmentation of --fix (augment.h)
  SourceKind source;         // what Hypothesis::source indexes
  // Appends the effect's hypotheses about y channel `target`.
  void (*enumerate)(const ResidualData& data, const LibraryOptions& options, int target,
                    std::vector<Hypothesis>& out);
  // The feature test's regressors for one log.
  Features (*features)(const Hypothesis& h, const ResidualLog& log);
  // The main fitted parameter from the coefficients (never empty).
  double (*main_parameter)(const Eigen::VectorXd& coef);
  // Whether the fit (`parameter` is main_parameter(coef)) is in the effect's
  // physical domain.
  bool (*plausible)(double parameter, const Eigen::VectorXd& coef);
  // Human-readable parameters, e.g. "delay = 2 steps on fc3 (gain 0.75)".
  std::string (*describe)(const Hypothesis& h, const ResidualData& data, double parameter);
  // --fix: the augmentation for the significant hypothesis `lead` of this
  // effect (the winner, or the best that has an augmentation): fills a's
  // channels, found_on, description and change. nullptr: the effect is named
  // and reported but has no augmentation.
  void (*plan)(const ResidualData& data, const Attribution& attribution, const HypothesisResult& lead,
               Augmentation& a);
  // Why the plan declines the significant hypothesis `lead` ("" when it does
  // not); nullptr: never.
  std::string (*not_planned)(const ResidualData& data, const Attribution& attribution, const HypothesisResult& lead);
  // --fix, after a confirmed change of this effect on `channels` (its
  // found_on): the effect that leaves nearly the same 1-step residual there
  // and what tells them apart, in words; nullptr: none is known.
  std::string (*look_alike)(const std::vector<std::string>& channels) = nullptr;
  // What a non-zero regressor row means, for the label of a hypothesis that
  // is not testable for too few of them (e.g. "the 1-step prediction passes
  // the rail"); nullptr: "a regressor is non-zero".
  const char* support_phrase = nullptr;
  // --fix: a simpler effect of the library, fewer parameters per channel
  // or no state where this one adds one, that a confirmed change of this
  // effect can imitate on its lead channel (a calibration curve
  // compressive at its top imitates a rail; the hysteresis inputs of one
  // motor, fine-tuned, imitate its loadcell's calibration curve), and
  // that fix() then tries in its place (FixResult::simpler); nullopt: none.
  std::optional<EffectKind> simpler = std::nullopt;
  // --fix: a richer effect of the library, more parameters per channel,
  // whose residual a confirmed change `confirmed` of this effect can stand in
  // for on its lead channel (a cross-talk between two loadcells of one group
  // imitates the group's calibration curve: neighbouring loadcells load
  // together, so each one's level explains the other's compression), and
  // that fix() then tries after the confirmation, applying it only when it
  // predicts the channels either claims significantly better
  // (FixResult::richer); nullptr, or nullopt for `confirmed`: none.
  std::optional<EffectKind> (*richer)(const Augmentation& confirmed) = nullptr;
};
// The table, in EffectKind order (the order hypotheses are enumerated in).
const std::vector<EffectInfo>& effect_library();

// Whether cross-talk `pair` forms a chain with one of `taken`: its target
// is a taken pair's target or source, or its source a taken pair's target.
// Without a chain, removing each pair's measured source is exact (the
// sensor model adds back the network's source, the same signal then).
bool forms_chain(const SensorCrosstalk& pair, const std::vector<SensorCrosstalk>& taken);
const EffectInfo& effect_info(EffectKind kind);

// The row's functions for any hypothesis:
// The regressors of a hypothesis for one log.
Features features(const Hypothesis& h, const ResidualLog& log);
// Human-readable parameters, e.g. "delay = 2 steps on fc3", from the fitted
// coefficients (`coef`: one per regressor, in target units per regressor unit).
std::string describe(const Hypothesis& h, const ResidualData& data, const Eigen::VectorXd& coef);
// The main fitted parameter (e.g. gain, friction in target units, drift
// rate); NaN without coefficients.
double main_parameter(const Hypothesis& h, const Eigen::VectorXd& coef);
// Whether the main parameter is in the effect's physical domain: a
// cross-talk picks up a fraction of its source (0 < gain < 1), a sensor
// delay explains the residual with a gain of at least 1/2 (1: all of it), a
// rail with a positive gain, and a calibration
// curve is increasing over the channel's range with slopes of at least 1/4
// at both ends (the flattest a fitted curve may be). The other effects
// take either sign (friction's sign follows the command convention; a drift
// may lower a reading). An implausible hypothesis is tested but never
// significant (attribution.h).
bool plausible(const Hypothesis& h, const Eigen::VectorXd& coef);
// Channel names as the descriptions list them: "fc1, fc3, fc4".
std::string join(const std::vector<std::string>& names);
// The name of the hypothesis' source channel (u, y or aux, by the effect's
// SourceKind); "" for an effect without one.
std::string source_name(const Hypothesis& h, const ResidualData& data);

// Every hypothesis of the library for these logs: per target channel, each
// effect's in table order (delays per delay, friction per muscle, drift,
// saturation per side where the signal sits at a rail: min_rail_share,
// a curve where the channel's range is not a point and
// options.sensor_curves, cross-talk per source, aux per aux channel).
std::vector<Hypothesis> enumerate_hypotheses(const ResidualData& data, const LibraryOptions& options);

}  // namespace hadynet::trainer::residual
