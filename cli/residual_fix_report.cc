// The --fix part of `hadynet residual`'s outputs (docs/residual.md, "--fix"):
// the JSON object, the Markdown section and the before/after plot.
#include "cli/residual_fix_report.h"

#include <algorithm>
#include <cstdio>

#include "cli/gnuplot.h"
#include "cli/number_text.h"

namespace hadynet::cli {

namespace {

namespace rs = trainer::residual;
using nlohmann::json;

json held_out_json(const rs::HeldOutError& e) {
  json ch = json::array();
  for (std::size_t c = 0; c < e.channels.size(); ++c) {
    const auto i = static_cast<Eigen::Index>(c);
    const auto& w = e.whiteness[c];
    ch.push_back({{"channel", e.channels[c]}, {"rmse", e.rmse(i)}, {"fit_percent", e.fit(i)},
                  {"ljung_box", {{"q", w.ljung_box.q}, {"dof", w.ljung_box.dof}, {"p_value", w.ljung_box.p_value}}},
                  {"white", w.white()}, {"acf_lags_outside", w.outside}, {"input_lags_outside", e.inputs_outside[c]}});
  }
  return {{"samples", e.samples}, {"verdict", e.verdict}, {"channels", ch}};
}

// A Diebold-Mariano test's fields.
json dm_json(const rs::DieboldMariano& t) {
  return {{"mean_loss_difference", t.mean}, {"statistic", t.stat}, {"rows", t.samples}, {"p_value", t.p_value}};
}

// "a, b, c".
std::string comma_separated(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + names[i];
  return out;
}

// The fields the simpler and the richer account share (FixResult::OtherAccount).
json other_account_json(const rs::FixResult::OtherAccount& a, const std::string& reference) {
  return {{"effect", a.effect},
          {"replaces", a.replaces},
          {"description", a.description},
          {"channels", a.channels},
          {"a_candidate", a.a_candidate},
          {"against_reference", {{"against", reference},
                                 {"mean_loss_difference", a.against_reference.mean},
                                 {"statistic", a.against_reference.stat},
                                 {"rows", a.against_reference.samples},
                                 {"p_value", a.against_reference.p_value}}},
          {"applied", a.applied}};
}

}  // namespace

nlohmann::json fix_json(const rs::FixResult& f, const rs::FixOptions& o) {
  json j = {{"status", f.status},
            {"changed", f.changed},
            {"none_gained", f.none_gained},
            {"look_alike", f.look_alike},
            {"selection_rule", rs::selection_rule_name(o.selection)},
            {"train_fraction", o.train_fraction},
            {"epochs", o.epochs},
            {"lr", o.lr},
            {"seed", o.seed},
            {"min_excess_null", o.min_excess_null ? json(*o.min_excess_null) : json(nullptr)},
            {"candidates_floor", f.candidates_floor ? json(*f.candidates_floor) : json(nullptr)},
            {"upper_rail_floor", f.upper_rail_floor ? json(*f.upper_rail_floor) : json(nullptr)},
            {"before", held_out_json(f.before)}};
  if (f.augmentation) {
    const rs::Augmentation& a = *f.augmentation;
    const auto* alignment = std::get_if<rs::TimeAlignment>(&a.change);
    j["augmentation"] = {{"effect", a.effect}, {"description", a.description}, {"channels", a.channels},
                         {"delay_steps", alignment != nullptr ? alignment->delay : 0}};
    if (const auto* removal = std::get_if<rs::CrosstalkRemoval>(&a.change)) {
      // pairs.front(): the winner's pair, which crosstalk::plan always takes.
      j["augmentation"]["source"] = removal->pairs.front().source;
      j["augmentation"]["gain"] = removal->pairs.front().gain;
      json pairs = json::array();
      for (const auto& x : removal->pairs) pairs.push_back({{"target", x.target}, {"source", x.source}, {"gain", x.gain}});
      j["augmentation"]["pairs"] = pairs;
    }
    if (const auto* curves = std::get_if<rs::CalibrationCurves>(&a.change)) {
      json list = json::array();
      for (const auto& c : curves->curves) list.push_back({{"channel", c.channel}, {"level", c.level}, {"reading", c.reading}});
      j["augmentation"]["curves"] = list;
    }
    const auto* derived = std::get_if<rs::DerivedCommandInputs>(&a.change);
    if (derived != nullptr && !derived->inputs.empty()) j["augmentation"]["derived_inputs"] = derived->inputs;
    if (!f.fitted_rates.empty()) j["augmentation"]["fitted_rates"] = f.fitted_rates;
  }
  if (f.changed) j["sensor_model"] = f.model.sensor.describe();
  if (f.control) j["control"] = held_out_json(*f.control);
  if (f.tried) {
    j["after"] = held_out_json(f.after);
    j["loss_history"] = f.loss_history;
    j["train_windows"] = f.train_windows;
    j["confirmation"] = {{"against", f.reference},
                         {"channels", f.confirmation_channels},
                         {"test", "Diebold-Mariano, one-sided, Newey-West variance"},
                         {"loss", rs::decision_loss_name(o.decision_loss)},
                         {"scale", rs::decision_scale_name(f.scale)},
                         {"pooling", rs::decision_pooling_name(o.decision_pooling)},
                         {"scale_note", f.scale_note},
                         {"own_channels", f.own_channels ? json{{"channels", f.own_channel_names},
                                                                 {"mean_loss_difference", f.own_channels->mean},
                                                                 {"statistic", f.own_channels->stat}}
                                                           : json()},
                         {"mean_loss_difference", f.confirmation.mean},
                         {"statistic", f.confirmation.stat},
                         {"bandwidth", f.confirmation.bandwidth},
                         {"rows", f.confirmation.samples},
                         {"folds", f.folds},
                         {"folds_note", f.folds_note},
                         {"first_fold", {{"rows", f.first_fold.samples},
                                         {"statistic", f.first_fold.stat},
                                         {"p_value", f.first_fold.p_value}}},
                         {"p_value", f.confirmation.p_value},
                         {"confirmed", f.changed}};
    // Wider plans tested after the confirmation (FixResult::extensions).
    j["extensions"] = json::array();
    for (const auto& e : f.extensions)
      j["extensions"].push_back({{"what", e.what},
                                 {"channels", e.channels},
                                 {"against", "the plan applied before it"},
                                 {"mean_loss_difference", e.test.mean},
                                 {"statistic", e.test.stat},
                                 {"rows", e.test.samples},
                                 {"p_value", e.test.p_value},
                                 {"applied", e.applied}});
    // The simpler account tried after the confirmation (FixResult::simpler).
    if (f.simpler) {
      const rs::FixResult::SimplerAccount& a = *f.simpler;
      json account = other_account_json(a, f.reference);
      account["flat_end"] = a.flat_end;
      if (a.gain_tested)
        account["confirmed_gain"] = {{"channels", a.gain_channels},
                                     {"mean_loss_difference", a.confirmed_gain.mean},
                                     {"statistic", a.confirmed_gain.stat},
                                     {"rows", a.confirmed_gain.samples},
                                     {"p_value", a.confirmed_gain.p_value}};
      j["simpler"] = account;
    }
    // The richer account tried after the confirmation (FixResult::richer).
    if (f.richer) {
      const rs::FixResult::RicherAccount& a = *f.richer;
      json account = other_account_json(a, f.reference);
      if (!a.own_channels.empty())
        account["own_channels"] = {{"channels", a.own_channels}, {"mean_loss_difference", a.own_gain}};
      if (a.gain_tested)
        account["gain_over_confirmed"] = {{"channels", a.gain_channels},
                                          {"mean_loss_difference", a.gain.mean},
                                          {"statistic", a.gain.stat},
                                          {"rows", a.gain.samples},
                                          {"p_value", a.gain.p_value}};
      j["richer"] = account;
    }
    // The rivals tested beside the selection's choice (FixResult::rivals).
    if (f.rivals) {
      const rs::FixResult::Rivals& r = *f.rivals;
      json plans = json::array();
      for (const auto& rv : r.plans) {
        json plan = {{"candidate", rv.candidate},
                     {"effect", rv.effect},
                     {"description", rv.description},
                     {"channels", rv.channels},
                     {"mean_loss_difference", rv.confirmation.mean},
                     {"statistic", rv.confirmation.stat},
                     {"rows", rv.confirmation.samples},
                     {"p_value", rv.confirmation.p_value},
                     {"own_channels_mean_loss_difference", rv.own_channels ? json(rv.own_channels->mean) : json()},
                     {"confirmed", rv.confirmed},
                     {"applied", rv.applied}};
        if (rv.gain)
          plan["gain_over_chosen"] = {{"mean_loss_difference", rv.gain->mean},
                                      {"statistic", rv.gain->stat},
                                      {"p_value", rv.gain->p_value}};
        plan["changed_channels"] = rv.changed_channels;
        plan["behind_largest_gain"] = rv.behind_largest ? dm_json(*rv.behind_largest) : json();
        plan["ties"] = rv.ties;
        plans.push_back(plan);
      }
      j["rivals"] = {{"against", f.reference},
                     {"levels", "Holm for the choice and its rivals: the i-th smallest p at alpha / (m - i)"},
                     {"chosen_effect", r.chosen_effect},
                     {"chosen_p_value", r.chosen_confirmation.p_value},
                     {"chosen_confirmed", r.chosen_confirmed},
                     {"chosen_changed_channels", r.chosen_changed_channels},
                     {"chosen_behind_largest_gain",
                      r.chosen_behind_largest ? dm_json(*r.chosen_behind_largest) : json()},
                     {"chosen_ties", r.chosen_ties},
                     {"gain_channels", r.gain_channels},
                     {"tie_break", rs::tie_break_name(r.tie_break)},
                     {"largest_gain_candidate",
                      r.largest_gain_candidate ? json(*r.largest_gain_candidate) : json()},
                     {"largest_gain_effect", r.largest_gain_candidate ? json(r.largest_gain_effect) : json()},
                     {"tie_broken", r.tie_broken},
                     {"plans", plans}};
    }
    json candidates = json::array();
    for (const auto& c : f.candidates)
      candidates.push_back({{"effect", c.effect},
                            {"description", c.description},
                            {"channels", c.channels},
                            {"screen_statistic", c.screen_statistic},
                            {"below_screen_floor", c.below_screen_floor},
                            {"from_drift_probe", c.from_drift_probe},
                            {"from_earlier_round", c.from_earlier_round},
                            {"rail_of_chosen_curve", c.rail_of_chosen_curve},
                            {"group_drift_gain", c.group_drift_gain
                                                     ? json{{"statistic", c.group_drift_gain->stat},
                                                            {"p_value", c.group_drift_gain->p_value},
                                                            {"mean_loss_difference", c.group_drift_gain->mean}}
                                                     : json()},
                            {"gave_way_to_group_drift", c.gave_way_to_group_drift},
                            {"selected_by_training_rows", c.selected_by_training_rows},
                            {"selection_statistic", c.selection.stat},
                            {"selection_p_value", c.selection.p_value},
                            {"selection_mean_loss_difference", c.selection.mean},
                            {"chosen", c.chosen}});
    j["candidates"] = candidates;
  }
  // The drift probes (FixResult::drift_probes), whether or not a fix was tried.
  j["drift_probes"] = json::array();
  for (const auto& p : f.drift_probes)
    j["drift_probes"].push_back({{"group", p.group},
                                 {"channels", p.channels},
                                 {"start_rate", p.start_rate},
                                 {"rate", p.rate},
                                 {"test", "Diebold-Mariano, one-sided, the unchanged network without minus with"},
                                 {"mean_loss_difference", p.gain.mean},
                                 {"statistic", p.gain.stat},
                                 {"rows", p.gain.samples},
                                 {"p_value", p.gain.p_value},
                                 {"p_adjusted", p.p_adjusted},
                                 {"candidate", p.candidate}});
  return j;
}

// Per channel: RMSE and fit before / fine-tune only / after, and Ljung-Box p before / after.
namespace {

std::string fix_table(const rs::FixResult& f) {
  auto find = [](const rs::HeldOutError& e, const std::string& name) -> int {
    for (std::size_t c = 0; c < e.channels.size(); ++c)
      if (e.channels[c] == name) return static_cast<int>(c);
    return -1;
  };
  const rs::HeldOutError& last = f.tried ? f.after : f.before;
  std::string m = "| channel | RMSE before | RMSE fine-tune only | RMSE after | fit before (%) | fit after (%) | "
                  "Ljung-Box p before | after | input lags outside before | after |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& name : last.channels) {
    const int b = find(f.before, name), c = f.control ? find(*f.control, name) : -1, a = find(f.after, name);
    auto cell = [](const rs::HeldOutError* e, int i, const char* fmt, int what) -> std::string {
      if (e == nullptr || i < 0) return "-";
      const auto k = static_cast<Eigen::Index>(i);
      const double v = what == 0 ? e->rmse(k) : what == 1 ? e->fit(k) : what == 2
                       ? e->whiteness[static_cast<std::size_t>(i)].ljung_box.p_value
                       : e->inputs_outside[static_cast<std::size_t>(i)];
      return num(fmt, v);
    };
    const rs::HeldOutError* after = f.tried ? &f.after : nullptr;
    const rs::HeldOutError* ctrl = f.control ? &*f.control : nullptr;
    m += "| " + name + " | " + cell(&f.before, b, "%.4g", 0) + " | " + cell(ctrl, c, "%.4g", 0) + " | " +
         cell(after, a, "%.4g", 0) + " | " + cell(&f.before, b, "%.1f", 1) + " | " + cell(after, a, "%.1f", 1) + " | " +
         cell(&f.before, b, "%.2g", 2) + " | " + cell(after, a, "%.2g", 2) + " | " + cell(&f.before, b, "%.0f", 3) +
         " | " + cell(after, a, "%.0f", 3) + " |\n";
  }
  return m;
}

}  // namespace

bool replaced_after_decision(const rs::FixResult& f) {
  return (f.simpler && f.simpler->applied) || (f.richer && f.richer->applied) ||
         std::any_of(f.extensions.begin(), f.extensions.end(), [](const auto& e) { return e.applied; });
}

std::string simpler_sentence(const rs::FixResult::SimplerAccount& s, const std::string& reference) {
  std::string m = "Simpler account: " + s.effect + " on ";
  m += comma_separated(s.channels);
  if (!s.a_candidate) m += " (not among the candidates)";
  m += ", against " + reference + " on their held-out rows (Diebold-Mariano, " +
       std::to_string(s.against_reference.samples) + " rows): mean loss difference " +
       num("%.3g", s.against_reference.mean) + ", p " + num("%.2g", s.against_reference.p_value);
  if (!s.gain_tested) return m + ": not confirmed, " + s.replaces + " kept";
  m += "; " + s.replaces + " against it on ";
  m += comma_separated(s.gain_channels);
  m += ": mean loss difference " + num("%.3g", s.confirmed_gain.mean) +
       ", p " + num("%.2g", s.confirmed_gain.p_value) + ": ";
  if (s.flat_end)
    return m + "the curve's end at the rail is as flat as its fit may be (a rail's signature), " + s.effect +
           " applied in its place";
  return m + (s.applied ? "no significant gain, " + s.effect + " applied in its place"
                        : "a significant gain, " + s.replaces + " kept");
}

std::string richer_sentence(const rs::FixResult::RicherAccount& r, const std::string& reference) {
  std::string m = "Richer account: " + r.effect + " (" + r.description + ")";
  if (!r.a_candidate) m += " (not among the candidates)";
  m += ", against " + reference + " on the held-out rows of " + comma_separated(r.channels) + " (Diebold-Mariano, " +
       std::to_string(r.against_reference.samples) + " rows): mean loss difference " +
       num("%.3g", r.against_reference.mean) + ", p " + num("%.2g", r.against_reference.p_value);
  if (!r.own_channels.empty())
    m += "; on its own channels (" + comma_separated(r.own_channels) + ") mean loss difference " +
         num("%.3g", r.own_gain);
  if (!r.gain_tested) return m + ": not confirmed, " + r.replaces + " kept";
  m += "; against " + r.replaces + " on " + comma_separated(r.gain_channels) + ": mean loss difference " +
       num("%.3g", r.gain.mean) + ", p " + num("%.2g", r.gain.p_value) + ": ";
  return m + (r.applied ? "a significant gain, " + r.effect + " applied in its place"
                        : "no significant gain, " + r.replaces + " kept");
}

// "3 channels", "1 channel".
std::string channel_count(std::size_t n) { return std::to_string(n) + (n == 1 ? " channel" : " channels"); }

// A plan's loss minus that of the plan of the largest gain (Rival::behind_largest).
std::string behind_largest(const rs::FixResult::Rivals& r, const rs::DieboldMariano& t, bool ties) {
  return "its loss minus that of the largest gain's plan (" + r.largest_gain_effect + ", no. " +
         std::to_string(r.largest_gain_candidate.value_or(0) + 1) + " of the candidates listed) " +
         num("%.3g", t.mean) + ", p " + num("%.2g", t.p_value) + (ties ? ": a tie" : ": not a tie");
}

std::string rivals_sentence(const rs::FixResult::Rivals& r, const std::string& reference) {
  const std::size_t m = r.plans.size() + 1;
  std::string text = "Rivals of " + r.chosen_effect + " (p " + num("%.2g", r.chosen_confirmation.p_value) +
                     (r.chosen_confirmed ? ", confirmed" : ", not confirmed") + "), each tested beside it against " +
                     reference + " on the held-out rows of its channels, at Holm's levels for " + std::to_string(m) +
                     " tests (the smallest p at " + num("%.3g", r.alpha / static_cast<double>(m)) + "):";
  bool applied = false;
  for (const auto& rv : r.plans) {
    text += " " + rv.effect + " (" + rv.description + "): mean loss difference " + num("%.3g", rv.confirmation.mean) +
            ", p " + num("%.2g", rv.confirmation.p_value);
    if (rv.own_channels) text += ", on its own channels " + num("%.3g", rv.own_channels->mean);
    text += rv.confirmed ? ", confirmed" : ", not confirmed";
    if (rv.gain) text += ", its gain over " + r.chosen_effect + " on the channels any confirmed one changes " +
                         num("%.3g", rv.gain->mean);
    if (rv.behind_largest) text += ", " + behind_largest(r, *rv.behind_largest, rv.ties);
    text += ", changing " + channel_count(rv.changed_channels.size());
    if (rv.applied) {
      text += ", applied in its place";
      applied = true;
    }
    text += ";";
  }
  text.pop_back();
  if (r.chosen_behind_largest)
    text += "; " + r.chosen_effect + " (changing " + channel_count(r.chosen_changed_channels.size()) + "): " +
            behind_largest(r, *r.chosen_behind_largest, r.chosen_ties);
  if (r.tie_broken)
    text += "; of the plan of the largest gain and those tied with it, the one changing the fewest channels is "
            "applied";
  if (!applied && r.chosen_confirmed) text += "; " + r.chosen_effect + " kept";
  return text;
}

std::string extension_sentence(const rs::FixResult::Extension& e) {
  std::string m = "Extension to " + e.what + ": ";
  m += comma_separated(e.channels);
  m += ", against the plan applied before it on their held-out rows (Diebold-Mariano, " +
       std::to_string(e.test.samples) + " rows): mean loss difference " + num("%.3g", e.test.mean) + ", p " +
       num("%.2g", e.test.p_value) + ": " + (e.applied ? "applied" : "not applied");
  return m;
}

std::string drift_probe_sentence(const rs::DriftProbe& p) {
  std::string m = "Drift probe of " + p.group + " (" + std::to_string(p.channels.size()) +
                  " channels, one load drift at one rate): ";
  if (!(p.start_rate > 0)) return m + "not probed, the channels carry no level";
  m += "rate " + num("%.3g", p.rate) + " per (unit s) on the selection's training rows";
  if (!(p.rate > 0)) return m + ": no drift";
  return m + ", the unchanged network's gain on the selection's judged rows (Diebold-Mariano, " +
         std::to_string(p.gain.samples) + " rows): mean loss difference " + num("%.3g", p.gain.mean) + ", p " +
         num("%.2g", p.gain.p_value) + " (Holm " + num("%.2g", p.p_adjusted) + "): " +
         (p.candidate ? "a candidate" : "not a candidate");
}

std::string fix_markdown(const rs::FixResult& f, const rs::FixOptions& o, const std::string& out,
                         const std::string& png) {
  std::string m = "\n## Fix (--fix)\n\n**" + f.status + "**";
  if (f.augmentation) m += ": " + f.augmentation->effect + ", " + f.augmentation->description;
  if (!f.look_alike.empty()) m += "\n\nNote: " + f.look_alike + ".";
  m += "\n\nFine-tuned " + std::to_string(o.epochs) + " epochs (batch norm frozen, Adam lr " + num("%g", o.lr) +
       ", seed " + std::to_string(o.seed) + ") on the first " + num("%.0f", 100 * o.train_fraction) +
       " % of each log's rows; every number below is on the remaining rows (" + std::to_string(f.before.samples) +
       " held-out rows, causal 1-step predictions of the measured values), the decision's mirrored fold "
       "apart. \"Fine-tune only\" is the same fine-tuning without the augmentation.\n\n";
  m += "Verdict before: " + f.before.verdict + "\n\n";
  for (const auto& p : f.drift_probes) m += drift_probe_sentence(p) + ".\n\n";
  if (f.tried) {
    const bool replaced = (f.simpler && f.simpler->applied) || (f.richer && f.richer->applied);
    const std::string chosen = f.simpler && f.simpler->applied ? f.simpler->replaces : f.richer ? f.richer->replaces : "";
    m += "Decision: the " + (replaced ? "chosen candidate (" + chosen + ")" : std::string("augmented model")) +
         " against " + f.reference + " on the held-out rows of ";
    m += comma_separated(f.confirmation_channels);
    m += std::string(" (one-sided Diebold-Mariano test of the standardised ") +
         rs::decision_loss_name(o.decision_loss) +
         (f.scale == rs::DecisionScale::kResidual ? " error relative to each channel's clean residual level" : " error") +
         (f.scale_note.empty() ? std::string() : " (" + f.scale_note + ")") +
         ", Newey-West variance over " +
         std::to_string(f.confirmation.bandwidth) + " lags, " + std::to_string(f.confirmation.samples) +
         " rows" + (f.folds > 1 ? " of " + std::to_string(f.folds) + " folds" : std::string()) +
         "): mean loss difference " + num("%.3g", f.confirmation.mean) + ", p " +
         num("%.2g", f.confirmation.p_value) +
         (f.folds > 1 ? " (the first fold alone: p " + num("%.2g", f.first_fold.p_value) + ")" : std::string()) +
         (f.folds_note.empty() ? std::string() : " (" + f.folds_note + ")") + ": **" + (f.changed ? "confirmed" : "not confirmed, nothing applied") +
         "**.\n\n";
    if (f.own_channels) {
      m += "Judged on every channel, it was also asked to predict its own channels (";
      m += comma_separated(f.own_channel_names);
      m += ") better than " + f.reference + ": mean loss difference " + num("%.3g", f.own_channels->mean) +
           (f.own_channels->mean > 0 ? " (it does)" : " (it does not)") + ".\n\n";
    }
    if (f.simpler) m += simpler_sentence(*f.simpler, f.reference) + ".\n\n";
    if (f.rivals) m += rivals_sentence(*f.rivals, f.reference) + ".\n\n";
    if (f.richer) m += richer_sentence(*f.richer, f.reference) + ".\n\n";
    for (const auto& e : f.extensions) m += extension_sentence(e) + ".\n\n";
    if (replaced_after_decision(f)) m += "The before/after below are the plan applied last.\n\n";
    m += "Verdict after (the augmented model on its own frame): " + f.after.verdict + "\n\n";
  }
  if (f.changed && !f.model.sensor.empty()) {
    m += "Sensor model of the fixed model (measured channels from the network's):\n\n";
    for (const auto& line : f.model.sensor.describe()) m += "- " + line + "\n";
    m += "\n";
  }
  if (!out.empty()) m += "Model written: `" + out + "`\n\n";
  if (!png.empty()) m += "![" + png + "](" + png + ")\n\n";
  return m + fix_table(f);
}


std::string fix_plot(const rs::FixResult& f, const std::string& png) {
  if (!f.tried) return "";
  // Per channel: held-out RMSE after and fine-tune only, relative to before.
  std::string s = "$r << EOD\n";
  for (std::size_t c = 0; c < f.after.channels.size(); ++c) {
    const std::string& name = f.after.channels[c];
    int b = -1;
    for (std::size_t i = 0; i < f.before.channels.size(); ++i)
      if (f.before.channels[i] == name) b = static_cast<int>(i);
    if (b < 0) continue;  // a channel the fix added
    const double before = f.before.rmse(b);
    const double after = f.after.rmse(static_cast<Eigen::Index>(c)) / before;
    const double control = f.control ? f.control->rmse(b) / before : after;
    s += std::to_string(c) + " " + num("%.6g", control) + " " + num("%.6g", after) + " " + name + "\n";
  }
  s += "EOD\n";
  s += "set terminal pngcairo size 1400,600 font 'sans,9' noenhanced\nset output " + gnuplot_quote(png) + "\n";
  s += "set title " + gnuplot_quote("held-out 1-step RMSE relative to before the fix (1 = unchanged): " +
                                    (f.augmentation ? f.augmentation->effect : std::string("")) + "; " +
                                    "verdict after: " + f.after.verdict) + "\n";
  s += "set style data histogram\nset style histogram cluster gap 1\nset style fill solid 0.8\nset grid y\n";
  s += "set yrange [0:*]\nset key top right\nset xtics rotate by -45 font 'sans,8'\n";
  s += "set arrow from graph 0, first 1 to graph 1, first 1 nohead dt 2 lc rgb 'black'\n";
  s += "plot $r using 2:xtic(4) title 'fine-tune only' lc rgb '#999999', '' using 3 title 'after the fix' lc rgb '#2ca02c'\n";
  return run_gnuplot(s, png);
}

}  // namespace hadynet::cli
