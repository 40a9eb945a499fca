#include "trainer/residual/augment.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <memory>
#include <cstdio>
#include <stdexcept>

#include "trainer/model_frame.h"
#include "trainer/residual/analysis.h"
#include "trainer/residual/drift_probe.h"

namespace hadynet::trainer::residual {

namespace {

int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

// Per log i: raw rows [rows[i].from, rows[i].to).
using RowSpan = std::vector<DecisionRows::Span>;

// Training data: raw rows [from, to) of each log in the model's frame; a
// frame aligned by a delay of s rows holds them in rows [from, to - s).
std::vector<LogSequence> training_rows(const std::vector<LogInput>& logs, const SensorModel& sensor,
                                       const FeatureLayout& layout, const RowSpan& rows) {
  std::vector<LogSequence> seqs;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    LogSequence s = in_model_frame(sensor, layout, logs[i].table, logs[i].file).sequence;
    const int keep = rows[i].to - sensor.max_delay() - rows[i].from;
    s.y = s.y.middleCols(rows[i].from, keep).eval();
    s.u = s.u.middleCols(rows[i].from, keep).eval();
    seqs.push_back(std::move(s));
  }
  return seqs;
}

// The first held-out row of each log: the first train_fraction of its rows
// are training rows, and at least d + 2 (d: the rows a sensor delay costs).
std::vector<int> held_out_starts(const std::vector<LogInput>& logs, double train_fraction, int d) {
  std::vector<int> split;
  for (const auto& in : logs) {
    const int T = static_cast<int>(in.table.rows());
    const int first = std::max(static_cast<int>(std::floor(train_fraction * T)), d + 2);
    if (first >= T - d) throw std::runtime_error(in.file + ": too short for --fix's time split");
    split.push_back(first);
  }
  return split;
}

}  // namespace

ResidualLevels residual_levels(const std::vector<std::string>& y_names, const Eigen::VectorXd& residual_level) {
  ResidualLevels out;
  double smallest = 0;
  for (Eigen::Index c = 0; c < residual_level.size(); ++c)
    if (residual_level(c) > 0 && (smallest == 0 || residual_level(c) < smallest)) smallest = residual_level(c);
  if (smallest == 0) return out;
  for (std::size_t c = 0; c < y_names.size() && static_cast<Eigen::Index>(c) < residual_level.size(); ++c) {
    const double level = residual_level(static_cast<Eigen::Index>(c));
    out[y_names[c]] = level > 0 ? level : smallest;
  }
  return out;
}

Segments standardised_loss(const HadynetModel& model, const HeldOutError& e, const std::vector<std::string>& channels,
                           DecisionLoss loss, const ResidualLevels* levels) {
  Segments out;
  for (const auto& name : channels) {
    const int c = index_of(e.channels, name);
    const int k = index_of(model.layout.y_names, name);
    if (c < 0 || k < 0) throw std::logic_error("--fix: channel " + name + " missing from a held-out evaluation");
    double scale = model.norm.y.std(k);
    if (levels != nullptr) {
      const auto level = levels->find(name);
      if (level == levels->end()) throw std::logic_error("--fix: channel " + name + " has no residual level on the null");
      scale *= std::sqrt(level->second);
    }
    const Segments& r = e.residuals[static_cast<std::size_t>(c)];
    if (out.empty()) out.assign(r.size(), Eigen::VectorXd());
    for (std::size_t s = 0; s < r.size(); ++s) {
      const Eigen::ArrayXd z = (r[s] / scale).array();
      const Eigen::ArrayXd per_row = loss == DecisionLoss::kSquared ? z.square().eval() : z.abs().eval();
      const Eigen::VectorXd term = per_row.matrix() / static_cast<double>(channels.size());
      out[s] = out[s].size() == 0 ? term : (out[s] + term).eval();
    }
  }
  return out;
}

namespace {
// The one of `values` whose `name_of` is `name` (the options' names: --decision-loss, ...); none otherwise.
template <typename E>
std::optional<E> value_named(const std::string& name, std::initializer_list<E> values, const char* (*name_of)(E)) {
  for (E value : values)
    if (name == name_of(value)) return value;
  return std::nullopt;
}
}  // namespace

const char* decision_loss_name(DecisionLoss loss) {
  return loss == DecisionLoss::kSquared ? "squared" : "absolute";
}

std::optional<DecisionLoss> decision_loss_named(const std::string& name) {
  return value_named(name, {DecisionLoss::kSquared, DecisionLoss::kAbsolute}, decision_loss_name);
}

const char* selection_rule_name(SelectionRule rule) {
  return rule == SelectionRule::kScreenOrder ? "screen-order" : "every-channel";
}

std::optional<SelectionRule> selection_rule_named(const std::string& name) {
  return value_named(name, {SelectionRule::kScreenOrder, SelectionRule::kEveryChannel}, selection_rule_name);
}

const char* tie_break_name(TieBreak rule) {
  return rule == TieBreak::kLargestGain ? "largest-gain" : "fewest-channels";
}

std::optional<TieBreak> tie_break_named(const std::string& name) {
  return value_named(name, {TieBreak::kLargestGain, TieBreak::kFewestChannels}, tie_break_name);
}

const char* decision_scale_name(DecisionScale scale) {
  return scale == DecisionScale::kStd ? "std" : "residual";
}

std::optional<DecisionScale> decision_scale_named(const std::string& name) {
  return value_named(name, {DecisionScale::kStd, DecisionScale::kResidual}, decision_scale_name);
}

const char* decision_pooling_name(DecisionPooling pooling) {
  return pooling == DecisionPooling::kRows ? "rows" : "logs";
}

std::optional<DecisionPooling> decision_pooling_named(const std::string& name) {
  return value_named(name, {DecisionPooling::kRows, DecisionPooling::kLogs}, decision_pooling_name);
}

std::size_t fewest_channels_among_ties(const std::vector<TestedPlan>& plans, std::size_t largest) {
  std::size_t pick = largest;
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const TestedPlan& p = plans[i];
    if (i == largest || !p.ties) continue;
    const TestedPlan& q = plans[pick];
    if (p.changed_channels < q.changed_channels || (p.changed_channels == q.changed_channels && p.gain > q.gain))
      pick = i;
  }
  return pick;
}

DecisionRows decision_rows(int T, int split, int d) {
  DecisionRows r;
  const int inner = static_cast<int>(std::floor(DecisionRows::kSelectionFraction * split));
  r.train = {0, split};
  r.held_out = {split, T - d};
  r.selection_train = {0, inner};
  r.selection_judged = {inner, split - d};
  r.mirrored_train = {T - split, T};
  r.mirrored_judged = {d + 2, T - split};
  r.can_select = inner >= d + 2 + DecisionRows::kMinSelectionRows &&
                 split - d - inner >= DecisionRows::kMinSelectionRows;
  r.mirrored = T - split - (d + 2) >= DecisionRows::kMinSelectionRows && T - split <= inner;
  return r;
}

namespace {

// The curve's channels' common rated top (CalibrationCurves::rated_top):
// none when one has no rated top or two differ.
std::optional<double> common_rated_top(const CalibrationCurves& change, const FixOptions& options) {
  std::optional<double> top;
  for (const SensorCurve& c : change.curves) {
    const RatedRange* range = rated_range_of(options.rated_ranges, c.channel);
    if (range == nullptr || !range->high || (top && *top != *range->high)) return std::nullopt;
    top = range->high;
  }
  return top;
}

}  // namespace

std::string why_not_fixable(const ResidualData& data, const Attribution& attribution, const HypothesisResult& r) {
  const EffectInfo& info = effect_info(r.hypothesis.kind);
  if (!info.plan) return info.augmentation;
  return info.not_planned ? info.not_planned(data, attribution, r) : "";
}

Eigen::Index TrainingRmse::row(const std::string& channel) const {
  const auto it = std::find(y_names.begin(), y_names.end(), channel);
  if (it == y_names.end()) throw std::logic_error("--fix: refine probes " + channel + ", not a y channel");
  return it - y_names.begin();
}

double TrainingRmse::operator()(const SensorModel& sensor, const std::string& channel) const {
  return all(sensor)(row(channel));
}

bool gains_significantly(const CandidateTrial& c, double alpha) {
  return c.selected_by_training_rows && c.selection.mean > 0 && c.selection.p_value < alpha;
}

std::string look_alike(const Augmentation& a) {
  const EffectInfo& info = effect_info(a.kind);
  return info.look_alike != nullptr ? info.look_alike(a.found_on) : "";
}

std::optional<std::size_t> chosen_candidate(const std::vector<CandidateTrial>& candidates, double alpha) {
  for (std::size_t k = 0; k < candidates.size(); ++k)
    if (gains_significantly(candidates[k], alpha)) return k;
  std::optional<std::size_t> chosen;
  double best = 0;
  bool any_judged = false;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const DieboldMariano& s = candidates[k].selection;
    any_judged = any_judged || candidates[k].selected_by_training_rows;
    if (candidates[k].selected_by_training_rows && s.mean > 0 && (!chosen || s.stat > best)) {
      best = s.stat;
      chosen = k;
    }
  }
  if (!any_judged) return 0;
  return chosen;
}

std::optional<std::size_t> best_candidate(const std::vector<CandidateTrial>& candidates, double alpha) {
  std::optional<std::size_t> significant, positive;
  bool any_judged = false;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const CandidateTrial& c = candidates[k];
    if (!c.selected_by_training_rows) continue;
    any_judged = true;
    if (gains_significantly(c, alpha) && (!significant || c.selection.stat > candidates[*significant].selection.stat))
      significant = k;
    if (c.selection.mean > 0 && (!positive || c.selection.stat > candidates[*positive].selection.stat)) positive = k;
  }
  if (!any_judged) return 0;
  return significant ? significant : positive;
}

namespace {

// The augmentation of significant hypothesis `r` (its effect's plan), with
// or without its group extension.
Augmentation planned_for(const ResidualData& data, const Attribution& attribution, const HypothesisResult& r,
                         bool group_extension) {
  Augmentation a;
  a.kind = r.hypothesis.kind;
  a.effect = r.effect;
  a.screen_statistic = floor_statistic(attribution, r);
  a.group_extension = group_extension;
  effect_info(a.kind).plan(data, attribution, r, a);
  return a;
}

// The significant hypotheses in the order plan_candidates plans them: the
// screen's (floor_statistic), except that a calibration curve stands at its
// group's summed excess share, the sum of floor_statistic over the group's
// significant curves. A curve's plan is one curve for the group's channels
// (effects.cc), so the evidence for it is the group's; the screen tests it
// channel by channel, where a loadcell at rest through most grasps dilutes
// each channel's share. On stop 86's curve sets 4282, 4368, 4383, 4447 and
// 4448 (development sets of this rule) no loadcell curve reached the five
// candidates behind the tendons' curve of one channel and cross-talks
// (docs/residual-experiments.md, "A curve stands at its group's summed excess share").
std::vector<const HypothesisResult*> planning_order(const ResidualData& data, const Attribution& attribution) {
  std::map<std::string, double> summed_curve_share;  // group -> summed floor_statistic of its significant curves
  std::vector<const HypothesisResult*> order;
  for (const auto& r : attribution.ranked) {
    if (!r.significant) continue;
    order.push_back(&r);
    if (r.hypothesis.kind == EffectKind::kSensorCurve)
      summed_curve_share[channel_group(data.y_names[static_cast<std::size_t>(r.hypothesis.target)])] +=
          floor_statistic(attribution, r);
  }
  const auto key = [&](const HypothesisResult* r) {
    if (r->hypothesis.kind != EffectKind::kSensorCurve) return floor_statistic(attribution, *r);
    return summed_curve_share[channel_group(data.y_names[static_cast<std::size_t>(r->hypothesis.target)])];
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](const HypothesisResult* a, const HypothesisResult* b) { return key(a) > key(b); });
  return order;
}

}  // namespace

std::vector<Augmentation> plan_candidates(const ResidualData& data, const Attribution& attribution, int count) {
  std::vector<Augmentation> out;
  const auto winner = attribution.winner();
  if (!winner || count < 1) return out;
  // The significant hypotheses whose effect --fix can add, in ranking order
  // (planning_order: a curve at its group's summed excess share), one per
  // class (the best of each, with its family; PlanClass): on fresh logs the
  // model's own misfit between neighbouring channels can fill the top of the
  // ranking with pairs of one effect (cross-talk fc1 -> fc2, fc2 -> fc1,
  // fc4 -> fc3 above a 2-step sensor delay; docs/residual.md). A sensor delay on a
  // channel the commands drive directly leaves nearly the residual of an
  // input delay on that channel alone, so the two can swap places
  // (docs/residual.md): an input-delay winner seen on one group only, the
  // only group where sensor delays are significant, or a sensor-delay winner
  // where sensor delays are significant on several groups beside an input
  // delay, is skipped and said (why_not_fixable); a sensor delay that shows
  // on other groups too is planned as the commands' dead time.
  // A candidate's class: its effect, and for a cross-talk whether its source
  // is in another group than its target. Between groups it is a mechanical
  // path (a tendon into a palm loadcell), planned as its pair alone; within
  // one it is a sensor array's neighbours, planned with the group's pairs:
  // two mechanisms, a candidate each. With one per effect, the model's own
  // misfit between neighbouring fingertips (fc2 -> fc1, gain 0.50) took
  // cross-talk's one place on the tension leak's set 2242, where the
  // plant's f5 -> fc6 ranked fourth at gain 0.165 and was never tried
  // (docs/residual-experiments.md, "A cross-talk between groups is its own candidate").
  // A calibration curve's class is its group as well: the curve of one
  // kind of sensor and that of another are two mechanisms too, and on
  // fresh sets a curve of the tendons f3/f4 (the model's misfit of the
  // tendon it fits worst) took the curve's one place from the loadcells'
  // (curve sets 4383, 4510, 4531; docs/residual-experiments.md, "A curve stands at its
  // group's summed excess share").
  struct PlanClass {
    EffectKind kind;
    bool between_groups;
    std::string curve_group;  // a calibration curve's group; else empty
    bool operator==(const PlanClass&) const = default;
  };
  const auto class_of_lead = [&](const HypothesisResult& r) {
    const bool crosstalk = r.hypothesis.kind == EffectKind::kCrosstalk;
    const std::string& target = data.y_names[static_cast<std::size_t>(r.hypothesis.target)];
    return PlanClass{r.hypothesis.kind,
                     crosstalk && channel_group(target) != channel_group(source_name(r.hypothesis, data)),
                     r.hypothesis.kind == EffectKind::kSensorCurve ? channel_group(target) : std::string()};
  };
  const auto class_of_plan = [](const Augmentation& a) {
    const auto* removal = std::get_if<CrosstalkRemoval>(&a.change);
    const bool between = a.kind == EffectKind::kCrosstalk && removal != nullptr && !removal->pairs.empty() &&
                         channel_group(removal->pairs.front().target) != channel_group(removal->pairs.front().source);
    const auto* curves = std::get_if<CalibrationCurves>(&a.change);
    return PlanClass{a.kind, between,
                     curves != nullptr && !curves->curves.empty() ? channel_group(curves->curves.front().channel)
                                                                  : std::string()};
  };
  std::vector<PlanClass> leads;
  const auto plan_of = [&](const HypothesisResult& r, bool group_extension) {
    return planned_for(data, attribution, r, group_extension);
  };
  // Why the winner cannot be added (its effect, or its plan finds nothing
  // to add); known before the loop, since a curve may be planned before it
  // (planning_order).
  std::string winner_not_fixable = why_not_fixable(data, attribution, *winner);
  if (winner_not_fixable.empty()) winner_not_fixable = plan_of(*winner, true).not_fixable;
  for (const HypothesisResult* lead_result : planning_order(data, attribution)) {
    const HypothesisResult& r = *lead_result;
    if (static_cast<int>(out.size()) >= count) break;
    if (!why_not_fixable(data, attribution, r).empty()) continue;
    // One candidate per class (PlanClass): by the class of the hypothesis
    // that led to a candidate, and by the class planned (a sensor delay that
    // shows on other groups plans a dead time: effects.cc). A lead whose plan
    // repeats a class already planned counts as having led.
    const auto planned = [&](const PlanClass& c) {
      return std::any_of(out.begin(), out.end(), [&](const Augmentation& b) { return class_of_plan(b) == c; });
    };
    const PlanClass lead = class_of_lead(r);
    if (planned(lead) || std::find(leads.begin(), leads.end(), lead) != leads.end()) continue;
    Augmentation a = plan_of(r, true);
    if (!a.not_fixable.empty()) continue;  // the plan found nothing to add (a curve without two distinct levels)
    if (planned(class_of_plan(a))) {
      leads.push_back(lead);
      continue;
    }
    if (out.empty() && r.label != winner->label && !winner_not_fixable.empty())
      a.description = "the winner (" + winner->effect + ": " + winner->label + ") is not added (" +
                      winner_not_fixable + "); the first significant effect that can be: " + r.label + "; " +
                      a.description;
    leads.push_back(lead);
    const bool extended = !a.extended_channels.empty();
    out.push_back(std::move(a));
    if (!extended || static_cast<int>(out.size()) >= count) continue;
    Augmentation family_alone = plan_of(r, false);
    if (family_alone.not_fixable.empty()) out.push_back(std::move(family_alone));
  }
  if (out.empty()) {  // nothing significant can be added: fix() says "not supported"
    Augmentation a;
    a.kind = winner->hypothesis.kind;
    a.effect = winner->effect;
    a.not_fixable = winner_not_fixable;
    a.description = winner->label;
    out.push_back(std::move(a));
  }
  return out;
}

namespace {

// Whether `confirmed` is a calibration curve whose end on the side of
// `rail`'s first clip of a channel the curve holds is as flat as the
// curve's fit may be (FixResult::SimplerAccount::flat_end; the channels
// hold one curve, CalibrationCurves::refine).
bool flat_end_at_rail(const Augmentation& confirmed, const Augmentation& rail) {
  const auto* curves = std::get_if<CalibrationCurves>(&confirmed.change);
  const auto* clips = std::get_if<OutputClips>(&rail.change);
  if (curves == nullptr || clips == nullptr) return false;
  for (const OutputClip& clip : clips->clips)
    for (const SensorCurve& curve : curves->curves)
      if (curve.channel == clip.channel) return CalibrationCurves::flat_at_end(curve, clip.side);
  return false;
}

}  // namespace

std::vector<Augmentation> earlier_candidates_for_next_round(const FixResult& fixed,
                                                            const std::vector<std::string>& confirmed) {
  std::vector<std::string> applied = confirmed;
  for (std::size_t k = 0; k < fixed.candidates.size(); ++k)
    if (fixed.candidates[k].chosen) applied.push_back(fixed.candidates[k].effect);
  // The confirmed change's other account of the same residual: a plan of
  // its simpler effect, or of the effect it is the simpler account of,
  // that shares a channel with it.
  const auto other_account = [&](const Augmentation& a) {
    if (!fixed.augmentation) return false;
    const Augmentation& c = *fixed.augmentation;
    if (effect_info(c.kind).simpler != a.kind && effect_info(a.kind).simpler != c.kind) return false;
    const auto shared = [&](const std::string& name) {
      return std::find(c.found_on.begin(), c.found_on.end(), name) != c.found_on.end() ||
             std::find(c.channels.begin(), c.channels.end(), name) != c.channels.end();
    };
    return std::any_of(a.channels.begin(), a.channels.end(), shared);
  };
  std::vector<Augmentation> out;
  for (const Augmentation& a : fixed.candidate_plans)
    if (a.not_fixable.empty() && std::find(applied.begin(), applied.end(), a.effect) == applied.end() &&
        !other_account(a))
      out.push_back(a);
  return out;
}

namespace {
bool addable_load_drift(const Augmentation& a) {
  return a.not_fixable.empty() && a.kind == EffectKind::kDriftLoad && !a.channels.empty();
}
// A load drift of `group`: one that holds a channel of it, whichever
// channel leads its family (a loadcell drift also shows on a tendon's
// tension, which can lead the screen's family: drift set 2762).
bool load_drift_of_group(const Augmentation& a, const std::string& group) {
  return addable_load_drift(a) && std::any_of(a.channels.begin(), a.channels.end(), [&](const std::string& name) {
           return channel_group(name) == group;
         });
}
// No plan can be added: the screen proposed nothing, or its winner's plan
// says why it cannot be added (plan_candidates).
bool none_addable(const std::vector<Augmentation>& planned) {
  return planned.empty() || !planned.front().not_fixable.empty();
}

// Whether plan `b` changes a channel of a group one of plan `a`'s channels is in.
bool shares_a_group(const Augmentation& a, const Augmentation& b) {
  return std::any_of(a.channels.begin(), a.channels.end(), [&](const std::string& name) {
    const std::string group = channel_group(name);
    return std::any_of(b.channels.begin(), b.channels.end(),
                       [&](const std::string& other) { return channel_group(other) == group; });
  });
}
}  // namespace

ProbePlace drift_probe_place(const std::vector<Augmentation>& planned, const std::string& group) {
  if (none_addable(planned)) return {0, true};
  const auto last = std::find_if(planned.rbegin(), planned.rend(),
                                 [&](const Augmentation& a) { return load_drift_of_group(a, group); });
  if (last != planned.rend()) return {static_cast<std::size_t>(planned.rend() - last), false};
  return {planned.size(), false};
}

bool gives_way_to_group_drift(const std::vector<Augmentation>& planned, std::size_t chosen, std::size_t probed) {
  if (chosen == probed || chosen >= planned.size() || probed >= planned.size()) return false;
  const Augmentation& probe = planned[probed];
  if (probe.kind != EffectKind::kDriftLoad || probe.channels.empty()) return false;
  return load_drift_of_group(planned[chosen], channel_group(probe.channels.front()));
}

std::vector<std::size_t> decision_rivals(const std::vector<Augmentation>& planned, std::size_t chosen,
                                         const std::vector<std::size_t>& probed) {
  std::vector<std::size_t> rivals;
  if (chosen >= planned.size()) return rivals;
  const Augmentation& a = planned[chosen];
  const auto addable = [](const Augmentation& p) { return p.not_fixable.empty() && !p.channels.empty(); };
  const auto is_probe = [&](std::size_t k) { return std::find(probed.begin(), probed.end(), k) != probed.end(); };
  // In the choice's groups, a curve's rivals: any other effect; a drift
  // with time's: a load drift; a load drift's: a curve or a drift with
  // time; a cross-talk within a group's (one that stands in for the group's
  // curve: its richer account): a curve or a load drift; a friction's: a
  // curve; any other effect's: none. Beyond them, below: every plan.
  const auto richer = effect_info(a.kind).richer;
  const bool stands_in_for_curve = richer && richer(a) == EffectKind::kSensorCurve;
  const auto is_rival = [&](const Augmentation& p) {
    if (!addable(p)) return false;
    switch (a.kind) {
      case EffectKind::kSensorCurve: return p.kind != EffectKind::kSensorCurve;
      case EffectKind::kDriftTime: return p.kind == EffectKind::kDriftLoad;
      case EffectKind::kDriftLoad: return p.kind == EffectKind::kSensorCurve || p.kind == EffectKind::kDriftTime;
      case EffectKind::kCrosstalk:
        return stands_in_for_curve && (p.kind == EffectKind::kSensorCurve || p.kind == EffectKind::kDriftLoad);
      case EffectKind::kFriction: return p.kind == EffectKind::kSensorCurve;
      default: return false;
    }
  };
  if (!addable(a)) return rivals;
  // A drift's rivals also: the drift probe's plans, of any group.
  const bool drift = a.kind == EffectKind::kDriftLoad || a.kind == EffectKind::kDriftTime;
  for (std::size_t k = 0; k < planned.size(); ++k) {
    if (k == chosen || !addable(planned[k])) continue;
    // Every choice's rivals also: every plan of the groups it does not
    // hold, which fix() tests only when it gained more than the choice
    // (rival_gain_floor).
    if ((drift && is_probe(k)) || !shares_a_group(a, planned[k]) || is_rival(planned[k])) rivals.push_back(k);
  }
  return rivals;
}

double rival_gain_floor(const Augmentation& chosen, const Augmentation& rival, double chosen_gain, bool probed) {
  const bool drift = chosen.kind == EffectKind::kDriftLoad || chosen.kind == EffectKind::kDriftTime;
  if (drift && probed) return 0.0;
  return shares_a_group(chosen, rival) ? 0.0 : std::max(chosen_gain, 0.0);
}

bool is_family_alone(const std::vector<Augmentation>& planned, std::size_t k) {
  return k > 0 && k < planned.size() && !planned[k].group_extension && planned[k - 1].kind == planned[k].kind &&
         !planned[k - 1].extended_channels.empty();
}

namespace {

// simpler_plans() and richer_plans(): the plans of effect `other` that
// account for planned[k]'s lead channel, else for another channel it was
// found on (their contracts).
std::vector<Augmentation> other_account_plans(const ResidualData& data, const Attribution& floorless,
                                              const std::vector<Augmentation>& planned, std::size_t k,
                                              std::optional<EffectKind> other) {
  std::vector<Augmentation> out;
  if (!other || planned[k].channels.empty()) return out;
  const std::string& lead = planned[k].channels.front();
  std::vector<std::string> found_on{lead};  // the lead first
  for (const std::string& c : planned[k].found_on)
    if (std::find(found_on.begin(), found_on.end(), c) == found_on.end()) found_on.push_back(c);
  const auto holds = [](const std::vector<std::string>& channels, const std::string& c) {
    return std::find(channels.begin(), channels.end(), c) != channels.end();
  };
  for (const Augmentation& a : planned)
    if (a.kind == *other && a.not_fixable.empty() && holds(a.channels, lead)) out.push_back(a);
  // Else the plans that hold a channel it was found on, of one group (the
  // first such plan's: a curve is a candidate once per group, and the
  // account is one plan and its wider form).
  if (out.empty())
    for (const Augmentation& a : planned)
      if (a.kind == *other && a.not_fixable.empty() && !a.channels.empty() &&
          (out.empty() || channel_group(a.channels.front()) == channel_group(out.front().channels.front())) &&
          std::any_of(a.channels.begin(), a.channels.end(), [&](const std::string& c) { return holds(found_on, c); }))
        out.push_back(a);
  if (out.empty()) {
    const auto best_on = [&](const auto& where) {
      return std::find_if(floorless.ranked.begin(), floorless.ranked.end(), [&](const HypothesisResult& r) {
        return r.significant && r.hypothesis.kind == *other && where(data.y_names[static_cast<std::size_t>(r.hypothesis.target)]);
      });
    };
    auto best = best_on([&](const std::string& c) { return c == lead; });
    if (best == floorless.ranked.end()) best = best_on([&](const std::string& c) { return holds(found_on, c); });
    if (best == floorless.ranked.end() || !why_not_fixable(data, floorless, *best).empty()) return out;
    const int target = best->hypothesis.target;
    // Without the floor, the effect's family (Attribution::family_of: every
    // channel where it is significant) can reach other groups and the other
    // side: the plan holds its channel's group and side only, that channel
    // first.
    Attribution view = floorless;
    const std::string group = channel_group(data.y_names[static_cast<std::size_t>(target)]);
    for (auto& r : view.ranked)
      if (r.hypothesis.kind == *other &&
          (channel_group(data.y_names[static_cast<std::size_t>(r.hypothesis.target)]) != group ||
           r.hypothesis.side != best->hypothesis.side))
        r.significant = false;
    std::stable_partition(view.ranked.begin(), view.ranked.end(), [](const HypothesisResult& r) { return r.significant; });
    const auto lead_at = std::find_if(view.ranked.begin(), view.ranked.end(), [&](const HypothesisResult& r) {
      return r.significant && r.hypothesis.kind == *other && r.hypothesis.target == target;
    });
    std::rotate(view.ranked.begin(), lead_at, lead_at + 1);
    Augmentation a = planned_for(data, view, view.ranked.front(), true);
    if (!a.not_fixable.empty()) return out;
    const bool extended = !a.extended_channels.empty();
    out.push_back(std::move(a));
    if (extended) {
      Augmentation family_alone = planned_for(data, view, view.ranked.front(), false);
      if (family_alone.not_fixable.empty()) out.push_back(std::move(family_alone));
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Augmentation& a, const Augmentation& b) { return a.channels.size() < b.channels.size(); });
  return out;
}

}  // namespace

std::vector<Augmentation> simpler_plans(const ResidualData& data, const Attribution& floorless,
                                       const std::vector<Augmentation>& planned, std::size_t k) {
  return other_account_plans(data, floorless, planned, k, effect_info(planned[k].kind).simpler);
}

std::vector<Augmentation> richer_plans(const ResidualData& data, const Attribution& floorless,
                                       const std::vector<Augmentation>& planned, std::size_t k) {
  const auto richer = effect_info(planned[k].kind).richer;
  return other_account_plans(data, floorless, planned, k, richer ? richer(planned[k]) : std::nullopt);
}

std::optional<Augmentation> on_whole_group(const std::vector<std::string>& y_names, const SensorModel& sensor,
                                           const Augmentation& a) {
  if (a.channels.empty()) return std::nullopt;
  const auto* bias = std::get_if<BiasState>(&a.change);
  const bool delay = a.kind == EffectKind::kSensorDelay && std::holds_alternative<TimeAlignment>(a.change);
  const bool drift = (a.kind == EffectKind::kDriftLoad || a.kind == EffectKind::kDriftTime) && bias != nullptr &&
                     !bias->drifts.empty();
  if (!delay && !drift) return std::nullopt;
  const std::string group = channel_group(a.channels.front());
  // A drift's common rate is re-estimated on a grid of its group's largest
  // rate (BiasState::refine): a load drift needs a positive one there.
  const auto positive_in_group = [&](const SensorDrift& x) { return x.rate > 0 && channel_group(x.channel) == group; };
  if (drift && bias->drifts.front().load &&
      std::none_of(bias->drifts.begin(), bias->drifts.end(), positive_in_group))
    return std::nullopt;
  const auto in_sensor = [&](const std::string& name) {
    if (delay)
      return std::any_of(sensor.delays.begin(), sensor.delays.end(),
                         [&](const SensorDelay& x) { return x.channel == name && x.steps > 0; });
    return std::any_of(sensor.drifts.begin(), sensor.drifts.end(),
                       [&](const SensorDrift& x) { return x.channel == name; });
  };
  Augmentation whole = a;
  std::string added;
  for (const auto& name : y_names) {
    if (channel_group(name) != group || in_sensor(name)) continue;
    if (std::find(a.channels.begin(), a.channels.end(), name) != a.channels.end()) continue;
    whole.channels.push_back(name);
    if (drift) std::get<BiasState>(whole.change).drifts.push_back({name, bias->drifts.front().load, 0.0});
    added += (added.empty() ? "" : ", ") + name;
  }
  if (added.empty()) return std::nullopt;
  whole.description += " (" + added + ": every channel of the group)";
  if (drift) {
    std::get<BiasState>(whole.change).common_rate = true;
    whole.description += ", one rate for the group";
  }
  return whole;
}

SensorModel sensor_after(const SensorModel& before, const Augmentation& a) {
  SensorModel s = before;
  std::visit([&](const auto& change) { change.add_to_sensor(s, a); }, a.change);
  return s;
}

bool Augmentation::carried_before_tuning() const {
  return std::visit([](const auto& c) { return c.carried_before_tuning(); }, change);
}

FeatureLayout augmented_layout(const FeatureLayout& layout, const Augmentation& a) {
  std::vector<std::string> y = layout.y_names, u = layout.u_names;
  std::visit([&](const auto& change) { change.add_to_channels(y, u); }, a.change);
  return feature_layout_from_names(y, u, layout.delta_groups);
}

HadynetModel augmented_model(const HadynetModel& model, const Augmentation& a,
                             const std::vector<LogSequence>& train_seqs) {
  HadynetModel m = model;
  m.detection.reset();
  m.ranges.reset();
  const auto fixed = m.provenance.find("residual_fix");
  m.provenance["residual_fix"] = (fixed == m.provenance.end() ? "" : fixed->second + "; then ") + a.effect + ": " +
                                 a.description;
  m.sensor = sensor_after(model.sensor, a);
  std::visit([&](const auto& change) { change.add_to_network(a, model, m, train_seqs); }, a.change);
  return m;
}

Attribution candidates_view(const Attribution& attribution, const FixOptions& options) {
  const Attribution view =
      !options.min_excess_null || *options.min_excess_null >= attribution.options.min_excess_null
          ? attribution
          : with_null_floor(attribution, *options.min_excess_null);
  return options.upper_rail_floor ? with_upper_rail_floor(view, *options.upper_rail_floor) : view;
}

FixResult fix(const HadynetModel& model, const std::vector<LogInput>& logs, const ResidualData& data,
              const Attribution& attribution, const FixOptions& options) {
  if (logs.size() != data.logs.size()) throw std::invalid_argument("--fix: logs and analysis differ");
  const DecisionLoss loss = options.decision_loss;  // every Diebold-Mariano test's per-row loss
  FixResult result;
  result.model = model;
  // The channels' unit in that loss (FixOptions::decision_scale).
  ResidualLevels null_levels;
  if (options.decision_scale == DecisionScale::kResidual) {
    if (attribution.null) null_levels = residual_levels(data.y_names, attribution.null->residual_level);
    if (null_levels.empty())
      result.scale_note = "no calibrated null: each channel's error is measured in its standard deviation (--decision-scale std)";
    else
      result.scale = DecisionScale::kResidual;
  }
  const ResidualLevels* levels = result.scale == DecisionScale::kResidual ? &null_levels : nullptr;
  const Attribution view = candidates_view(attribution, options);
  if (view.null) result.candidates_floor = view.options.min_excess_null;
  if (view.null && view.options.upper_rail_floor_applies()) result.upper_rail_floor = view.options.upper_rail_floor;
  std::vector<Augmentation> planned = plan_candidates(data, view, options.candidates);
  // An earlier round's plans (FixOptions::earlier_candidates), tried after
  // this round's: none this round's screen plans too (kind and channels).
  std::vector<Augmentation> earlier;
  if (options.earlier_candidates != nullptr) {
    for (const Augmentation& a : *options.earlier_candidates) {
      if (static_cast<int>(earlier.size()) >= options.candidates) break;
      const bool planned_now = std::any_of(planned.begin(), planned.end(), [&](const Augmentation& p) {
        return p.kind == a.kind && p.channels == a.channels;
      });
      if (a.not_fixable.empty() && !planned_now) earlier.push_back(a);
    }
  }
  // Rows a sensor delay costs at the end of each log, before or after: the
  // largest over every candidate, so that all are judged on the same rows.
  int d = model.sensor.max_delay();
  for (const auto& a : planned) d = std::max(d, sensor_after(model.sensor, a).max_delay());
  for (const auto& a : earlier) d = std::max(d, sensor_after(model.sensor, a).max_delay());

  // The rows each model is fine-tuned on and judged on (decision_rows):
  // the first fold's held-out rows are the same for every model reported.
  const std::vector<int> split = held_out_starts(logs, options.train_fraction, d);
  RowSpan train_part, held_out_part, selection_train, selection_judged, mirrored_train, mirrored_judged;
  bool can_select = true, mirrored_fold_fits = true;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    const DecisionRows r = decision_rows(static_cast<int>(logs[i].table.rows()), split[i], d);
    train_part.push_back(r.train);
    held_out_part.push_back(r.held_out);
    selection_train.push_back(r.selection_train);
    selection_judged.push_back(r.selection_judged);
    mirrored_train.push_back(r.mirrored_train);
    mirrored_judged.push_back(r.mirrored_judged);
    can_select = can_select && r.can_select;
    mirrored_fold_fits = mirrored_fold_fits && r.mirrored;
  }
  // Each model is fed the logs in its own frame and judged on the measured rows of `rows`.
  auto eval_rows = [&](const HadynetModel& m, const std::vector<Eigen::VectorXf>& pbs, const RowSpan& rows) {
    std::vector<HeldOutLog> out;
    for (std::size_t i = 0; i < logs.size(); ++i) {
      HeldOutLog e;
      e.raw = &logs[i];
      e.measured = log_sequence(logs[i].table, logs[i].file, m.layout);
      e.frame = in_model_frame(m.sensor, m.layout, logs[i].table, logs[i].file).sequence;
      e.pb = pbs[i];
      e.first = rows[i].from;
      e.end = rows[i].to;
      out.push_back(std::move(e));
    }
    return out;
  };
  auto eval_logs = [&](const HadynetModel& m, const std::vector<Eigen::VectorXf>& pbs) {
    return eval_rows(m, pbs, held_out_part);
  };
  auto state_pbs = [&](const HadynetModel& m) {
    std::vector<Eigen::VectorXf> pbs;
    for (const auto& log : data.logs) pbs.push_back(m.params.pb.row(m.state_index(log.seq.state)).transpose());
    return pbs;
  };
  // A fine-tuned model (its states' PBs) judged on `rows`: with the
  // diagnostics a report shows on the held-out part, errors alone elsewhere.
  auto judged = [&](const HadynetModel& m, const RowSpan& rows) {
    const HeldOutDetail detail = &rows == &held_out_part ? HeldOutDetail::kWithDiagnostics : HeldOutDetail::kErrorsOnly;
    return held_out_error(m, eval_rows(m, state_pbs(m), rows), detail);
  };
  const FineTuneOptions tuning{options.epochs, options.batch, options.lr, options.seed, 1};
  std::vector<Eigen::VectorXf> before_pbs;
  for (const auto& log : data.logs) before_pbs.push_back(log.pb);
  result.before = held_out_error(model, eval_logs(model, before_pbs));
  result.before.verdict = verdict_text(attribution);

  // The rows of `rows` (less the rows a sensor delay costs at either end)
  // fed to `network` with the PBs `pbs` in the measured frame, for a sensor
  // model the criterion is asked about: refine()'s and refit()'s probe.
  auto training_rmse_on = [&](const HadynetModel& network, const std::vector<Eigen::VectorXf>& pbs,
                              const RowSpan& rows) {
    auto net = std::make_shared<HadynetModel>(network);
    const auto training_logs = [&eval_logs, &d, net, pbs, rows](const SensorModel& sensor) {
      net->sensor = sensor;
      std::vector<HeldOutLog> train = eval_logs(*net, pbs);
      for (std::size_t i = 0; i < train.size(); ++i) {
        train[i].first = std::max(rows[i].from, ResidualLog::kFirstRow + d);
        train[i].end = std::min(rows[i].to, train[i].measured.steps() - d);
      }
      return train;
    };
    TrainingRmse training_rmse;
    training_rmse.y_names = network.layout.y_names;
    training_rmse.all = [net, training_logs](const SensorModel& sensor) {
      const std::vector<HeldOutLog> train = training_logs(sensor);
      return Eigen::VectorXd(held_out_error(*net, train, HeldOutDetail::kErrorsOnly).rmse);
    };
    training_rmse.windows = [net, training_logs, steps = network.train_steps](const SensorModel& sensor) {
      const std::vector<HeldOutLog> train = training_logs(sensor);
      return window_rmse(*net, train, steps);
    };
    return training_rmse;
  };
  // What an augmentation re-estimates before fine-tuning (drift: the rates;
  // curve: the slopes), probing the unchanged network with a sensor model on
  // the rows of `rows`: the rows its fine-tuning will see.
  auto refined = [&](Augmentation a, const RowSpan& rows, std::vector<double>* fitted) {
    const TrainingRmse training_rmse = training_rmse_on(model, before_pbs, rows);
    if (auto* curves = std::get_if<CalibrationCurves>(&a.change)) curves->rated_top = common_rated_top(*curves, options);
    std::vector<double> rates;
    std::visit([&](auto& change) { change.refine(a, model.sensor, training_rmse, rates); }, a.change);
    if (fitted != nullptr) *fitted = std::move(rates);
    return a;
  };
  HadynetModel probe = model;  // the drift probe's: the unchanged network with a sensor model it sets

  // The drift probe (drift_probe.h): the regression screen rarely lists a
  // slow drift, and lists it on a family of one or two channels, so every
  // channel group is asked with the unchanged network whether a load drift
  // at one re-estimated rate predicts the selection's judged rows better.
  // Every group that does is one more candidate, where drift_probe_place()
  // puts it, the smallest adjusted p first (candidate_drift_probes). The
  // selection then chooses among them as among any.
  std::vector<std::size_t> probed;  // their indices in `planned`
  if (options.drift_probe_alpha > 0 && can_select) {
    DriftProbeRows rows;
    rows.refined = [&](const Augmentation& plan) { return refined(plan, selection_train, nullptr); };
    // The unchanged network without a drift is every group's reference: judged once.
    std::optional<HeldOutError> unchanged;
    rows.loss = [&](const SensorModel& sensor, const std::vector<std::string>& channels) {
      const auto judged_rows = [&] {
        probe.sensor = sensor;
        return held_out_error(probe, eval_rows(probe, before_pbs, selection_judged), HeldOutDetail::kErrorsOnly);
      };
      if (sensor != model.sensor) return standardised_loss(model, judged_rows(), channels, loss);
      if (!unchanged) unchanged = judged_rows();
      return standardised_loss(model, *unchanged, channels, loss);
    };
    result.drift_probes = probe_drifts(model, data, rows, options.drift_probe_alpha);
    for (const DriftProbe* p : candidate_drift_probes(result.drift_probes)) {
      const ProbePlace place = drift_probe_place(planned, p->group);
      if (place.replaces_all) planned.clear();
      planned.insert(planned.begin() + static_cast<std::ptrdiff_t>(place.at),
                     group_drift_plan(p->channels, data.logs.front().dt_s, p->start_rate));
      for (std::size_t& k : probed)
        if (k >= place.at) ++k;
      probed.push_back(place.at);
    }
  }
  // The earlier round's plans after this round's (a winner of this round
  // that cannot be added gives way to them).
  std::size_t first_earlier = planned.size();
  if (!earlier.empty()) {
    if (!planned.empty() && !planned.front().not_fixable.empty()) planned.clear();
    first_earlier = planned.size();
    planned.insert(planned.end(), earlier.begin(), earlier.end());
  }
  if (planned.empty()) {
    result.status = "no significant effect";
    return result;
  }
  if (!planned.front().not_fixable.empty()) {
    result.augmentation = planned.front();
    result.status = "not supported: " + planned.front().effect + ": " + planned.front().not_fixable;
    return result;
  }

  // The parts of a calibration curve's fine-tuning (tune(): the curve
  // refitted before each but the first; 4: after 5, 10 and 15 of the
  // default 20 epochs). Chosen on development curve sets 3880-3899
  // (docs/residual-experiments.md, "The curve refitted during fine-tuning (stop 85)"):
  // the fitted curve read on average 0.91 of the plant's at its top knot
  // before fine-tuning, 0.94 after one refit half-way, 0.98 after three.
  constexpr int kCurveFits = 4;
  struct Tuned {
    HadynetModel model;
    std::vector<double> loss_history;
    long train_windows = 0;
  };
  // A model fine-tuned on the rows of `rows` with `a` (nullptr: the
  // control, no augmentation). A calibration curve's fine-tuning runs in
  // kCurveFits parts, and before each but the first the curve is fitted
  // again (CalibrationCurves::refit) on the network as fine-tuned so far,
  // its PBs and the same rows; the next part reads the logs through it and
  // continues the same optimiser (FineTuneState), so the parts alone change
  // nothing (a refit that keeps the slopes rebuilds the curve's readings
  // from them, which can round their last digits). `a` then holds the refitted
  // curve. `untuned`: the augmented model before fine-tuning, with `a` as
  // it ends.
  auto tune = [&](Augmentation* a, const RowSpan& rows, HadynetModel* untuned = nullptr) {
    Tuned t;
    const SensorModel sensor = a != nullptr ? sensor_after(model.sensor, *a) : model.sensor;
    const FeatureLayout layout = a != nullptr ? augmented_layout(model.layout, *a) : model.layout;
    // The augmented layout first (aux adds a channel, friction commands), then its training data.
    const auto seqs = training_rows(logs, sensor, layout, rows);
    t.model = a != nullptr ? augmented_model(model, *a, seqs) : model;
    const auto states = ensure_states(t.model, seqs, before_pbs);
    if (untuned != nullptr) *untuned = t.model;
    // A curve's fine-tuning in kCurveFits parts, the curve refitted before each but the first.
    auto* curves = a != nullptr ? std::get_if<CalibrationCurves>(&a->change) : nullptr;
    const int parts = curves != nullptr ? std::max(1, std::min(kCurveFits, tuning.epochs)) : 1;
    auto part_seqs = seqs;
    FineTuneState optimiser;  // carried from part to part: one fine-tuning, its data re-read
    int done = 0;             // epochs run
    for (int part = 1; part <= parts; ++part) {
      if (part > 1) {
        curves->refit(*a, model.sensor, training_rmse_on(t.model, state_pbs(t.model), rows), done);
        part_seqs = training_rows(logs, sensor_after(model.sensor, *a), layout, rows);
        HadynetModel started = augmented_model(model, *a, part_seqs);  // the refitted curve and its description
        t.model.sensor = started.sensor;
        t.model.provenance = started.provenance;
        if (untuned != nullptr) {
          ensure_states(started, part_seqs, before_pbs);
          *untuned = std::move(started);
        }
      }
      FineTuneOptions o = tuning;
      o.first_epoch = done + 1;
      o.epochs = tuning.epochs * part / parts - done;
      for (const double l : fine_tune(t.model, part_seqs, states, o, &t.train_windows,
                                      reading_loss_weights(t.model.sensor, layout.y_names, part_seqs), &optimiser))
        t.loss_history.push_back(l);
      done += o.epochs;
    }
    t.model.check_consistent();
    return t;
  };
  // The model's channels that any of `sets` holds, in the model's order.
  const auto in_model_order = [&](std::initializer_list<const std::vector<std::string>*> sets) {
    std::vector<std::string> out;
    for (const auto& name : model.layout.y_names)
      if (std::any_of(sets.begin(), sets.end(), [&](const std::vector<std::string>* set) {
            return std::find(set->begin(), set->end(), name) != set->end();
          }))
        out.push_back(name);
    return out;
  };
  auto channels_of = [&](const Augmentation& a) {
    if (a.judged_on_every_channel) return model.layout.y_names;
    std::vector<std::string> out;
    for (const auto& name : a.found_on) {
      if (index_of(model.layout.y_names, name) < 0) continue;
      if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
    }
    return out;
  };

  // Selection (several candidates), on the training rows alone: in the
  // screen's order, each candidate and the control are fine-tuned on the
  // first 75 % of the training rows and compared on the rest (one-sided
  // Diebold-Mariano); the first significant at alpha is chosen, else the
  // clearest gain (chosen_candidate). The held-out rows play no part, so
  // the decision below tests one candidate at the full alpha (or, with its
  // rivals, each at Holm's levels: decision_rivals).
  std::size_t chosen = 0;
  std::vector<std::size_t> rivals;  // decision_rivals() that gained: tested beside the choice
  // A plan's record among the candidates, before it is judged.
  const auto trial_of = [&](const Augmentation& plan) {
    CandidateTrial c;
    c.effect = plan.effect;
    c.description = plan.description;
    c.channels = channels_of(plan);
    c.screen_statistic = plan.screen_statistic;
    return c;
  };
  for (std::size_t k = 0; k < planned.size(); ++k) {
    CandidateTrial c = trial_of(planned[k]);
    c.from_drift_probe = std::find(probed.begin(), probed.end(), k) != probed.end();
    c.from_earlier_round = k >= first_earlier;
    c.below_screen_floor = !c.from_drift_probe && !c.from_earlier_round && attribution.null &&
                           c.screen_statistic < attribution.options.min_excess_null;
    result.candidates.push_back(std::move(c));
  }
  result.candidate_plans = planned;
  if (planned.size() > 1 && can_select) {
    const Tuned control = tune(nullptr, selection_train);
    const HeldOutError control_rows = judged(control.model, selection_judged);
    const bool every_channel = options.selection == SelectionRule::kEveryChannel;
    // Each judged candidate's errors on the selection's judged rows.
    std::vector<std::optional<HeldOutError>> judged_rows(planned.size());
    const auto judge = [&](std::size_t k) {
      // Re-estimated on the selection's training rows alone (the rows it is judged on stay unseen).
      Augmentation a = refined(planned[k], selection_train, nullptr);
      const Tuned t = tune(&a, selection_train);
      const HeldOutError& rows = judged_rows[k].emplace(judged(t.model, selection_judged));
      CandidateTrial& c = result.candidates[k];
      // On the channels the re-estimated plan changes (a drift at rate 0 left out: BiasState::refine).
      c.channels = channels_of(a);
      const std::vector<std::string>& judged_on = every_channel ? model.layout.y_names : c.channels;
      c.selection = diebold_mariano(standardised_loss(model, control_rows, judged_on, loss),
                                    standardised_loss(model, rows, judged_on, loss));
      c.selected_by_training_rows = true;
      c.description = a.description;  // as judged: re-estimated on the selection's training rows
    };
    for (std::size_t k = 0; k < planned.size(); ++k) {
      judge(k);
      // chosen_candidate's choice: the rest are not needed
      if (!every_channel && gains_significantly(result.candidates[k], attribution.options.alpha)) break;
    }
    const std::optional<std::size_t> supported = every_channel
                                                     ? best_candidate(result.candidates, attribution.options.alpha)
                                                     : chosen_candidate(result.candidates, attribution.options.alpha);
    if (!supported) {
      // The clearest of them (the largest statistic), labelled as what it is.
      std::size_t best = 0;
      for (std::size_t k = 1; k < result.candidates.size(); ++k)
        if (result.candidates[k].selected_by_training_rows &&
            result.candidates[k].selection.stat > result.candidates[best].selection.stat)
          best = k;
      const CandidateTrial& c = result.candidates[best];
      char stat[32];
      std::snprintf(stat, sizeof stat, "%.2f", c.selection.stat);
      result.none_gained = true;
      result.status = "unexplained structure: no candidate predicted the selection's rows better than fine-tuning "
                      "alone, so none was tested on the held-out rows (the clearest, not confirmed: " +
                      c.effect + " (" + c.description + "), Diebold-Mariano statistic " + stat + ")";
      return result;
    }
    chosen = *supported;
    // A drift family gives way to the drift probe's plan of its group when
    // that plan gains on the selection's rows too and predicts the channels
    // either changes better there (gives_way_to_group_drift).
    // (The probe of the family's first group that holds one of its channels.)
    const auto group_probe = std::find_if(probed.begin(), probed.end(), [&](std::size_t k) {
      return gives_way_to_group_drift(planned, chosen, k);
    });
    if (judged_rows[chosen] && group_probe != probed.end()) {
      const std::size_t g = *group_probe;
      if (!judged_rows[g]) judge(g);
      CandidateTrial& family = result.candidates[chosen];
      const CandidateTrial& group = result.candidates[g];
      const std::vector<std::string> either = in_model_order({&family.channels, &group.channels});
      family.group_drift_gain = diebold_mariano(standardised_loss(model, *judged_rows[chosen], either, loss),
                                                standardised_loss(model, *judged_rows[g], either, loss));
      if (group.selection.mean > 0 && family.group_drift_gain->mean > 0) {
        family.gave_way_to_group_drift = true;
        chosen = g;
      }
    }
    // A chosen calibration curve whose group's channels top out together
    // on the training rows (CalibrationCurves::tops_together: a rail's
    // signature) has the upper rail of its lead channel (its simpler
    // account's plans: the rail extended to its group, then its family
    // alone, in plan_candidates()' order) among its rivals, planned here
    // when no candidate is that rail: the simpler account asks for the rail
    // only once the curve is confirmed, and a curve fitted to a rail's data
    // can fail where the rail would not. Only an upper rail: the tops are
    // the group's highest levels.
    if (const auto* curves = std::get_if<CalibrationCurves>(&planned[chosen].change);
        curves != nullptr && CalibrationCurves::tops_together(curves->group_tops, curves->group_lowest)) {
      std::vector<Augmentation> rails = simpler_plans(data, with_null_floor(attribution, 0), planned, chosen);
      const auto upper = [](const Augmentation& a) {
        const auto* clips = std::get_if<OutputClips>(&a.change);
        return clips != nullptr && !clips->clips.empty() &&
               std::all_of(clips->clips.begin(), clips->clips.end(), [](const OutputClip& c) { return c.side > 0; });
      };
      const auto is_candidate = [&](const Augmentation& rail) {
        return std::any_of(planned.begin(), planned.end(), [&](const Augmentation& a) {
          return a.kind == rail.kind && a.channels == rail.channels;
        });
      };
      if (!rails.empty() && std::all_of(rails.begin(), rails.end(), upper) &&
          std::none_of(rails.begin(), rails.end(), is_candidate)) {
        std::reverse(rails.begin(), rails.end());  // simpler_plans: fewest channels first
        for (Augmentation& rail : rails) {
          planned.push_back(std::move(rail));
          CandidateTrial c = trial_of(planned.back());
          c.rail_of_chosen_curve = true;
          result.candidates.push_back(std::move(c));
          judged_rows.emplace_back();
        }
        result.candidate_plans = planned;
      }
    }
    // Rivals (decision_rivals): those that gained on the selection's rows
    // too (more than rival_gain_floor) are tested beside the choice.
    for (const std::size_t k : decision_rivals(planned, chosen, probed)) {
      if (!judged_rows[k]) judge(k);
      const double gain_floor = rival_gain_floor(planned[chosen], planned[k], result.candidates[chosen].selection.mean,
                                                 result.candidates[k].from_drift_probe);
      if (result.candidates[k].selection.mean > gain_floor) rivals.push_back(k);
    }
  }
  result.candidates[chosen].chosen = true;

  if (options.control) {
    const Tuned c = tune(nullptr, train_part);
    result.control = judged(c.model, held_out_part);
  }
  const HeldOutError& reference = result.control ? *result.control : result.before;
  result.reference = result.control ? "fine-tuning alone" : "the unchanged model";

  // The mirrored fold (FixOptions::folds 2): each plan and the reference
  // fine-tuned on each log's last rows, [T - split, T), and judged on its
  // first, [d + 2, T - split); its rows join every test.
  if (options.folds == 2 && !mirrored_fold_fits) {
    result.folds_note = "the mirrored fold was not judged: a log is too short for it, or --train-fraction is below "
                        "4/7 (its rows would overlap the rows that chose the candidate)";
  }
  const bool mirrored = options.folds == 2 && mirrored_fold_fits;
  std::optional<HeldOutError> mirrored_reference;
  if (mirrored) {
    mirrored_reference = options.control ? judged(tune(nullptr, mirrored_train).model, mirrored_judged)
                                         : held_out_error(model, eval_rows(model, before_pbs, mirrored_judged),
                                                          HeldOutDetail::kErrorsOnly);
    result.folds = 2;
  }

  // A plan re-estimated and fine-tuned on the training part of each fold
  // judged (the mirrored fold's when it is).
  struct FoldTrial {
    Augmentation tested;
    std::vector<double> rates;
    HadynetModel untuned;
    Tuned after;
    HeldOutError rows;                     // the first fold's held-out rows
    std::optional<HeldOutError> mirrored;  // the mirrored fold's
  };
  const auto fold_trial = [&](const Augmentation& plan) {
    FoldTrial t;
    t.tested = refined(plan, train_part, &t.rates);
    t.after = tune(&t.tested, train_part, &t.untuned);
    t.rows = judged(t.after.model, held_out_part);
    if (mirrored) {
      Augmentation on_mirrored = refined(plan, mirrored_train, nullptr);
      t.mirrored = judged(tune(&on_mirrored, mirrored_train).model, mirrored_judged);
    }
    return t;
  };
  // One-sided Diebold-Mariano on `channels`, on every fold judged: the loss
  // of `a` (first fold, mirrored fold) minus that of `b` (with
  // DecisionPooling::kLogs, each log of each fold in its own level).
  const auto compare = [&](const HeldOutError& a, const std::optional<HeldOutError>& a_mirrored, const HeldOutError& b,
                           const std::optional<HeldOutError>& b_mirrored, const std::vector<std::string>& channels) {
    Segments a_loss = standardised_loss(model, a, channels, loss, levels);
    Segments b_loss = standardised_loss(model, b, channels, loss, levels);
    if (a_mirrored && b_mirrored) {
      for (auto& segment : standardised_loss(model, *a_mirrored, channels, loss, levels))
        a_loss.push_back(std::move(segment));
      for (auto& segment : standardised_loss(model, *b_mirrored, channels, loss, levels))
        b_loss.push_back(std::move(segment));
    }
    if (options.decision_pooling == DecisionPooling::kLogs) relative_to_segment_level(a_loss, b_loss);
    return diebold_mariano(a_loss, b_loss);
  };
  const auto significant = [&](const DieboldMariano& t) {
    return t.mean > 0 && t.p_value < attribution.options.alpha;
  };
  // The model's channels a plan changes (its found_on, once each).
  const auto own_channels_of = [&](const Augmentation& plan) {
    std::vector<std::string> own;
    for (const auto& name : plan.found_on)
      if (index_of(model.layout.y_names, name) >= 0 && std::find(own.begin(), own.end(), name) == own.end())
        own.push_back(name);
    return own;
  };

  // The decision of one plan, planned[k]: fine-tuned on the whole training
  // part and judged against the reference on the held-out rows of the
  // channels it was found on (the plan's found_on, of the model's own
  // channels: the aligned, cleaned, clipped, drifting or friction channels;
  // for an aux channel, the channels its significant hypotheses explain;
  // for a calibration curve every channel: Augmentation::judged_on_every_channel),
  // as re-estimated (a drift at rate 0 left out: BiasState::refine). A
  // change judged on every channel (a calibration curve) must also predict
  // its own channels better than the reference, on every fold judged (the
  // mean loss difference there, no test): a curve that gains elsewhere
  // while its own channels read worse is not their calibration
  // (FixResult::own_channels).
  struct Decision {
    FoldTrial trial;
    std::vector<std::string> channels;
    DieboldMariano first_fold, confirmation;  // the first fold alone; every fold
    std::optional<DieboldMariano> own;        // a curve's own channels, every fold
    std::vector<std::string> own_names;
    // The test's p, or 1 when the plan gains nothing or its own channels read worse.
    double p() const {
      return confirmation.mean > 0 && (!own || own->mean > 0) ? confirmation.p_value : 1.0;
    }
  };
  const auto decide = [&](std::size_t k) {
    Decision c;
    c.trial = fold_trial(planned[k]);
    c.channels = channels_of(c.trial.tested);
    c.first_fold = compare(reference, std::nullopt, c.trial.rows, std::nullopt, c.channels);
    c.confirmation = compare(reference, mirrored_reference, c.trial.rows, c.trial.mirrored, c.channels);
    if (c.trial.tested.judged_on_every_channel) {
      c.own_names = own_channels_of(c.trial.tested);
      if (!c.own_names.empty())
        c.own = compare(reference, mirrored_reference, c.trial.rows, c.trial.mirrored, c.own_names);
    }
    result.candidates[k].channels = c.channels;
    if (!result.candidates[k].selected_by_training_rows) result.candidates[k].description = c.trial.tested.description;
    return c;
  };
  const double alpha = attribution.options.alpha;
  Decision decided = decide(chosen);
  bool confirmed = decided.p() < alpha;
  if (!rivals.empty()) {
    // The choice and its rivals at Holm's levels for m tests (the i-th
    // smallest p at alpha / (m - i), until one is not below its level):
    // confirmed where the Holm-adjusted p is below alpha.
    std::vector<Decision> others;
    for (const std::size_t k : rivals) others.push_back(decide(k));
    FixResult::Rivals r;
    r.chosen_effect = planned[chosen].effect;
    r.chosen_confirmation = decided.confirmation;
    r.alpha = alpha;
    std::vector<double> p = {decided.p()};
    for (const Decision& o : others) p.push_back(o.p());
    const std::vector<double> adjusted = holm_adjust(p);
    std::vector<bool> holm(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) holm[i] = adjusted[i] < alpha;
    r.chosen_confirmed = holm[0];
    // Of those confirmed, the one that predicts the channels any of them
    // changes best on the held-out rows: the largest gain over the choice
    // there (the choice's own is 0).
    for (std::size_t i = 0; i < p.size(); ++i)
      if (holm[i])
        r.gain_channels = in_model_order({&r.gain_channels, i == 0 ? &decided.channels : &others[i - 1].channels});
    std::optional<std::size_t> best;  // index into others; none: the choice
    double best_gain = 0;
    bool any = r.chosen_confirmed;
    for (std::size_t i = 0; i < others.size(); ++i) {
      FixResult::Rivals::Rival rv;
      rv.candidate = rivals[i];
      rv.effect = planned[rivals[i]].effect;
      rv.description = others[i].trial.tested.description;
      rv.channels = others[i].channels;
      rv.confirmation = others[i].confirmation;
      rv.own_channels = others[i].own;
      rv.confirmed = holm[i + 1];
      if (rv.confirmed) {
        rv.gain = compare(decided.trial.rows, decided.trial.mirrored, others[i].trial.rows, others[i].trial.mirrored,
                          r.gain_channels);
        if ((!any && !best) || rv.gain->mean > best_gain) {
          best = i;
          best_gain = rv.gain->mean;
        }
        any = true;
      }
      r.plans.push_back(std::move(rv));
    }
    confirmed = any;
    r.tie_break = options.tie_break;
    r.chosen_changed_channels = decided.trial.tested.channels;
    for (std::size_t i = 0; i < others.size(); ++i) r.plans[i].changed_channels = others[i].trial.tested.channels;
    if (any) {
      r.largest_gain_candidate = best ? rivals[*best] : chosen;
      r.largest_gain_effect = best ? r.plans[*best].effect : r.chosen_effect;
    }
    if (any && options.tie_break == TieBreak::kFewestChannels) {
      // The confirmed plans the largest gain's does not beat significantly
      // tie with it; of those, the one changing the fewest channels, the
      // larger gain among equally few (the choice's gain is 0).
      const FoldTrial& largest = best ? others[*best].trial : decided.trial;
      const auto ties = [&](const FoldTrial& t, std::optional<DieboldMariano>& behind) {
        behind = compare(t.rows, t.mirrored, largest.rows, largest.mirrored, r.gain_channels);
        return !significant(*behind);
      };
      // plans[0]: the choice; plans[i + 1]: others[i] (a plan not
      // confirmed never ties).
      std::vector<TestedPlan> plans(others.size() + 1);
      plans[0].changed_channels = r.chosen_changed_channels.size();
      if (best && r.chosen_confirmed) plans[0].ties = r.chosen_ties = ties(decided.trial, r.chosen_behind_largest);
      for (std::size_t i = 0; i < others.size(); ++i) {
        FixResult::Rivals::Rival& rv = r.plans[i];
        plans[i + 1].changed_channels = rv.changed_channels.size();
        plans[i + 1].gain = rv.gain ? rv.gain->mean : 0.0;
        if (rv.confirmed && !(best && i == *best)) plans[i + 1].ties = rv.ties = ties(others[i].trial, rv.behind_largest);
      }
      const std::size_t largest_plan = best ? *best + 1 : 0;
      const std::size_t applied_plan = fewest_channels_among_ties(plans, largest_plan);
      r.tie_broken = applied_plan != largest_plan;
      best = applied_plan == 0 ? std::nullopt : std::optional<std::size_t>(applied_plan - 1);
    }
    if (best) {
      r.plans[*best].applied = true;
      decided = std::move(others[*best]);
      chosen = rivals[*best];  // the plan decided on, from here on
    }
    result.rivals = std::move(r);
  }
  result.confirmation_channels = decided.channels;
  result.first_fold = decided.first_fold;
  result.confirmation = decided.confirmation;
  if (decided.own) {
    result.own_channels = decided.own;
    result.own_channel_names = decided.own_names;
  }

  // The trial's plan becomes the applied one.
  Tuned after;
  std::optional<HeldOutError> mirrored_after;
  const auto apply = [&](FoldTrial& t) {
    result.augmentation = t.tested;
    result.fitted_rates = std::move(t.rates);
    result.untuned = std::move(t.untuned);
    result.loss_history = t.after.loss_history;
    result.train_windows = t.after.train_windows;
    result.after = std::move(t.rows);
    mirrored_after = std::move(t.mirrored);
    after = std::move(t.after);
  };
  apply(decided.trial);

  // The simpler account (FixResult::simpler): a confirmed change that can
  // imitate a simpler effect on a channel it was found on (its lead
  // first) stands only if it predicts the channels either claims
  // significantly better than the simpler plan does, once that plan is
  // confirmed against the reference itself. Tried on the plan with the
  // fewest channels; its extended plan, if any, is then a wider plan. Plans
  // that need more rows than the candidates were judged on are not tried
  // (a simpler effect that delays).
  const Augmentation* extended_of_applied = is_family_alone(planned, chosen) ? &planned[chosen - 1] : nullptr;
  const Augmentation* applied_plan = &planned[chosen];  // the applied change before its re-estimation (refined)
  bool applied_extended = !planned[chosen].extended_channels.empty();
  std::vector<Augmentation> simpler;
  if (confirmed && effect_info(planned[chosen].kind).simpler)  // the ranking re-floored only when it can be asked
    simpler = simpler_plans(data, with_null_floor(attribution, 0), planned, chosen);
  const auto judged_rows_suffice = [&](const std::vector<Augmentation>& plans) {
    return std::all_of(plans.begin(), plans.end(),
                       [&](const Augmentation& a) { return sensor_after(model.sensor, a).max_delay() <= d; });
  };
  // The other account's plan `plan` fine-tuned on each fold (`t`) and
  // judged against the reference on its channels; gain_channels: where
  // either account claims something (the confirmed change's channels and
  // the plan's).
  const auto other_account = [&](FixResult::OtherAccount& account, const Augmentation& plan, FoldTrial& t) {
    account.effect = plan.effect;
    account.replaces = planned[chosen].effect;
    account.description = plan.description;
    account.a_candidate = std::any_of(planned.begin(), planned.end(), [&](const Augmentation& a) {
      return a.kind == plan.kind && a.channels == plan.channels;
    });
    t = fold_trial(plan);
    account.channels = channels_of(t.tested);  // as re-estimated, as the decision's
    account.against_reference = compare(reference, mirrored_reference, t.rows, t.mirrored, account.channels);
    account.gain_channels = result.confirmation_channels;
    for (const auto& name : account.channels)
      if (std::find(account.gain_channels.begin(), account.gain_channels.end(), name) == account.gain_channels.end())
        account.gain_channels.push_back(name);
  };
  // The other account's first plan (`plans`' front, trial `t`) applied in
  // the confirmed change's place; its last, if another, is then the wider plan.
  const auto apply_account = [&](FoldTrial& t, const std::vector<Augmentation>& plans) {
    apply(t);
    applied_plan = &plans.front();
    extended_of_applied = plans.size() > 1 ? &plans.back() : nullptr;
    applied_extended = !plans.front().extended_channels.empty();
  };
  if (!simpler.empty() && judged_rows_suffice(simpler)) {
    const Augmentation& plan = simpler.front();
    FixResult::SimplerAccount account;
    FoldTrial t;
    other_account(account, plan, t);
    if (significant(account.against_reference)) {
      account.gain_tested = true;
      account.confirmed_gain = compare(t.rows, t.mirrored, result.after, mirrored_after, account.gain_channels);
      account.flat_end = flat_end_at_rail(*result.augmentation, plan);
      account.applied = account.flat_end || !significant(account.confirmed_gain);
    }
    if (account.applied) apply_account(t, simpler);
    result.simpler = std::move(account);
  }

  // The richer account (FixResult::richer): a confirmed change that a richer
  // effect's plan may explain (a cross-talk within a group, the group's
  // calibration curve) gives way to that plan only when the plan is
  // confirmed against the reference itself and predicts the channels either
  // claims significantly better than the change. Tried on the plan with the
  // fewest channels; its extended plan, if any, is then a wider plan.
  std::vector<Augmentation> richer;
  if (confirmed && !(result.simpler && result.simpler->applied) && effect_info(planned[chosen].kind).richer)
    richer = richer_plans(data, with_null_floor(attribution, 0), planned, chosen);
  if (!richer.empty() && judged_rows_suffice(richer)) {
    const Augmentation& plan = richer.front();
    FixResult::RicherAccount account;
    FoldTrial t;
    other_account(account, plan, t);
    bool confirmed_itself = significant(account.against_reference);
    if (plan.judged_on_every_channel) {  // as the decision asks of such a plan
      account.own_channels = own_channels_of(plan);
      if (!account.own_channels.empty()) {
        account.own_gain = compare(reference, mirrored_reference, t.rows, t.mirrored, account.own_channels).mean;
        confirmed_itself = confirmed_itself && account.own_gain > 0;
      }
    }
    if (confirmed_itself) {
      account.gain_tested = true;
      account.gain = compare(result.after, mirrored_after, t.rows, t.mirrored, account.gain_channels);
      account.applied = significant(account.gain);
    }
    if (account.applied) apply_account(t, richer);
    result.richer = std::move(account);
  }

  // A wider plan, tested only after the test before it was significant (a fixed
  // sequence at alpha; FixResult::extensions): the plan applied so far
  // against `wider` on the held-out rows of the channels `wider` adds;
  // applied when significant. Returns whether it was applied.
  // A drift's whole group (one common rate) changes the rates of the
  // channels it had too, so it is judged on all its channels.
  const auto try_wider = [&](const Augmentation& wider, const std::string& what) {
    const Augmentation& current = *result.augmentation;
    const auto* bias = std::get_if<BiasState>(&wider.change);
    const bool all_its_channels = bias != nullptr && bias->common_rate;
    FixResult::Extension e;
    e.what = what;
    for (const auto& name : wider.channels)
      if (index_of(model.layout.y_names, name) >= 0 &&
          (all_its_channels ||
           std::find(current.channels.begin(), current.channels.end(), name) == current.channels.end()))
        e.channels.push_back(name);
    if (e.channels.empty()) return false;
    FoldTrial t = fold_trial(wider);
    e.test = compare(result.after, mirrored_after, t.rows, t.mirrored, e.channels);
    e.applied = significant(e.test);
    result.extensions.push_back(e);
    if (e.applied) apply(t);
    return e.applied;
  };
  // A confirmed family alone: does its extended plan predict the channels it
  // adds better? (The plant's delay of every loadcell aligned on a few, the
  // others left late: docs/residual-experiments.md, "Wider plans, tested after the
  // confirmation".) Then a delay seen beyond its family, on the channels of
  // its group the test did not find it on (an acquisition chain delays
  // every channel it carries, and a channel that barely moves hides it).
  //
  // A confirmed drift: straight to every channel of its group at one rate,
  // whatever the test found (sensors of one kind age together, and the
  // 1-step residual shows little of a drift: docs/residual-experiments.md, "A drift
  // across its group"); that plan holds its extended plan's channels, so
  // the one test replaces both. Its plan is the applied one before
  // re-estimation, so that each fold re-estimates the rate on its own
  // training rows.
  if (confirmed) {
    const bool drift = std::holds_alternative<BiasState>(applied_plan->change);
    bool beyond_family = applied_extended;
    if (extended_of_applied != nullptr && !drift)
      beyond_family = try_wider(*extended_of_applied, "its group's channels where the test finds the same effect");
    if (beyond_family || drift) {
      const Augmentation& plan = drift ? *applied_plan : *result.augmentation;
      if (const auto whole = on_whole_group(model.layout.y_names, model.sensor, plan))
        try_wider(*whole, "every channel of its group");
    }
  }

  // The residual analysis of the augmented model (in its own frame), against
  // the calibrated null of the same model when the analysis had one.
  // An aux column the model now predicts is no longer an unused channel.
  const auto drop_predicted_aux = [](ResidualData& residuals) {
    for (std::size_t a = residuals.aux_names.size(); a-- > 0;) {
      if (index_of(residuals.y_names, residuals.aux_names[a]) < 0) continue;
      residuals.aux_names.erase(residuals.aux_names.begin() + static_cast<std::ptrdiff_t>(a));
      for (auto& log : residuals.logs) {
        Eigen::MatrixXd kept(log.aux.rows() - 1, log.aux.cols());
        kept << log.aux.topRows(static_cast<Eigen::Index>(a)),
            log.aux.bottomRows(log.aux.rows() - 1 - static_cast<Eigen::Index>(a));
        log.aux = kept;
      }
    }
  };
  ResidualData again = compute_residuals(after.model, logs, "state");
  drop_predicted_aux(again);
  LibraryOptions library_after = options.library;
  library_after.sensor_curves = options.reference != nullptr && !options.reference->empty();
  const std::vector<Hypothesis> hypotheses_after = enumerate_hypotheses(again, library_after);
  if (options.reference != nullptr && !options.reference->empty()) {
    ResidualData ref = compute_residuals(with_reference_sensor(after.model, options.reference_sensor),
                                         with_model_dead_time(after.model, *options.reference),
                                         options.reference_pb_choice);
    drop_predicted_aux(ref);
    const NullCalibration null = calibrate_null(again, ref, hypotheses_after, attribution.options);
    result.after.verdict = verdict_text(attribute(again, hypotheses_after, attribution.options, &null));
  } else {
    result.after.verdict = verdict_text(attribute(again, hypotheses_after, attribution.options));
  }
  result.tried = true;

  char p[32];
  std::snprintf(p, sizeof p, "%.2g", result.confirmation.p_value);
  if (!confirmed) {
    const auto& a = *result.augmentation;
    const bool own_worse = result.own_channels && result.own_channels->mean <= 0 && significant(result.confirmation);
    result.status = "unexplained structure: adding " + a.effect + " (" + a.description + ") did not beat " +
                    result.reference + " on the held-out rows of " +
                    (own_worse ? "its own channels (it did on every channel, Diebold-Mariano p " + std::string(p) + ")"
                               : (a.judged_on_every_channel ? "every channel" : "the channels it was found on") +
                                     std::string(" (Diebold-Mariano p ") + p + ")");
    if (result.rivals) {
      char level[32];
      std::snprintf(level, sizeof level, "%.3g", alpha / static_cast<double>(result.rivals->plans.size() + 1));
      for (const auto& rv : result.rivals->plans) {
        char rival_p[32];
        std::snprintf(rival_p, sizeof rival_p, "%.2g", rv.confirmation.p_value);
        result.status += ", nor did its rival " + rv.effect + " (" + rv.description + ", Diebold-Mariano p " + rival_p + ")";
      }
      result.status += std::string(" (tested at Holm's levels, the smallest p at ") + level + ")";
    }
    return result;
  }
  result.model = std::move(after.model);
  result.changed = true;
  result.status = "fixed";
  result.look_alike = look_alike(*result.augmentation);
  return result;
}

}  // namespace hadynet::trainer::residual
