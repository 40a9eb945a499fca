// hadynet residual: the analysis half of the residual loop (docs/residual.md,
// docs/architecture.md §5): multi-step residuals of a model over logs, the
// residual tests (whiteness, independence), the effect library's feature
// tests and their attribution, a Markdown report with PNG plots and a JSON
// with every number.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/number_text.h"
#include "cli/options.h"
#include "cli/residual_fix_report.h"
#include "cli/residual_report.h"
#include "cli/threads_option.h"
#include "datalog/log_reader.h"
#include "datalog/robot_profile.h"
#include "trainer/held_out_logs.h"
#include "trainer/model_file.h"
#include "trainer/residual/analysis.h"
#include "trainer/residual/augment.h"
#include "trainer/residual/rated_ranges.h"

namespace hadynet::cli {

namespace {

namespace rs = trainer::residual;
using nlohmann::json;

// The logs of the calibrated null: the --reference logs when given (never a
// log under test), else the held-out logs stored in the model, leaving out
// any whose rows a log under test holds (then they are not other data).
// `source` says where they came from, or why there are none.
std::vector<rs::LogInput> reference_logs(const trainer::HadynetModel& model, const std::string& model_path,
                                         const std::vector<std::string>& args, const std::vector<rs::LogInput>& inputs,
                                         std::string* source) {
  std::vector<rs::LogInput> reference;
  if (!args.empty()) {
    for (const auto& path : trainer::expand_log_paths(args)) {
      for (const auto& in : inputs)
        if (std::filesystem::equivalent(in.file, path))
          throw std::invalid_argument("--reference " + path + " is also a log under test; a null must be other logs");
      reference.push_back({datalog::read_log(path), path});
    }
    *source = "--reference";
    return reference;
  }
  if (model.held_out_logs.empty()) {
    *source = "the model stores no held-out logs (trained with --held-out 0 or before models stored them); "
              "give clean logs with --reference";
    return reference;
  }
  std::size_t overlapping = 0;
  for (const auto& stored : model.held_out_logs) {
    const std::string name = model_path + ": held-out log " + stored.name;
    datalog::LogTable table = datalog::parse_log(stored.text, name);
    bool in_test = false;
    for (const auto& in : inputs) in_test = in_test || trainer::contains_rows(in.table, table);
    if (in_test) {
      ++overlapping;
      continue;
    }
    reference.push_back({std::move(table), name});
  }
  // The null tests the same hypotheses, aux_* channels included: the aux
  // channels (the aux_* columns every log has, in order) must be the same.
  if (!reference.empty() && rs::common_aux_names(reference) != rs::common_aux_names(inputs)) {
    *source = "the model's held-out logs have other aux_* columns than the logs under test; give clean logs "
              "with the same columns with --reference";
    return {};
  }
  *source = "the model's held-out logs: rows of its training logs no training window used";
  if (overlapping > 0) {
    *source += "; " + std::to_string(overlapping) + " of " + std::to_string(model.held_out_logs.size()) +
               " left out because a log under test holds their rows";
    if (reference.empty()) *source = "every held-out log stored in the model is part of a log under test; "
                                     "give other clean logs with --reference";
  }
  return reference;
}

// The console summary: fit per channel and horizon, whiteness, the top of the ranking, the verdict.
void print_summary(const rs::Analysis& a, const std::string& pb_choice, bool fixing) {
  const auto& d = a.data;
  std::printf("%zu logs, %zu channels; multi-step fit over %ld window starts\n%s\n", d.logs.size(),
              d.y_names.size(), a.horizon.samples, rs::pb_summary(d, pb_choice).c_str());
  std::printf("%-10s %9s %9s %11s %11s %9s %6s\n", "channel", "fit h=1", "RMSE h=1",
              ("fit h=" + std::to_string(a.horizon.horizon)).c_str(),
              ("RMSE h=" + std::to_string(a.horizon.horizon)).c_str(), "LB p", "white");
  for (std::size_t c = 0; c < d.y_names.size(); ++c) {
    const auto r = static_cast<Eigen::Index>(c);
    const Eigen::Index H = a.horizon.horizon - 1;
    std::printf("%-10s %8.1f%% %9.4g %10.1f%% %11.4g %9.2g %6s\n", d.y_names[c].c_str(), a.horizon.fit(r, 0),
                a.horizon.rmse(r, 0), a.horizon.fit(r, H), a.horizon.rmse(r, H), a.whiteness[c].ljung_box.p_value,
                a.whiteness[c].white() ? "yes" : "no");
  }
  std::printf("%s\n", rs::floors_summary(a).c_str());
  std::printf("\n%ld hypotheses tested; top of the ranking:\n", a.attribution.tested);
  for (std::size_t i = 0; i < a.attribution.ranked.size() && i < 10; ++i) {
    const auto& r = a.attribution.ranked[i];
    char null_part[64] = "";  // with a calibrated null: what the hypothesis explains there, and its excess
    if (a.attribution.null)
      std::snprintf(null_part, sizeof null_part, ", null %.4f: %.2f x clean", r.null_explained_std, r.excess_share);
    std::printf("  %c %-62s explained %6.3f (std %.4f%s)  p(Holm) %.2g  %s\n", r.significant ? '*' : ' ',
                r.label.c_str(), r.explained, r.explained_std, null_part, r.p_adjusted,
                rs::hypothesis_status(r, a.attribution.options));
  }
  std::printf("\nverdict: %s\n", a.verdict.c_str());
  if (a.attribution.winner() && !fixing)
    std::printf("(the screen's candidate: only --fix, which adds it and compares with fine-tuning alone on held-out\n"
                " rows, confirms an effect or reports unexplained structure)\n");
}

// The --fix console table: held-out RMSE before / fine-tune only / after.
void print_fix(const rs::FixResult& fixed) {
  std::printf("\nfix: %s%s\n", fixed.status.c_str(),
              fixed.augmentation ? (": " + fixed.augmentation->description).c_str() : "");
  if (!fixed.look_alike.empty()) std::printf("note: %s\n", fixed.look_alike.c_str());
  for (const auto& p : fixed.drift_probes) std::printf("%s\n", drift_probe_sentence(p).c_str());
  const rs::HeldOutError& e = fixed.tried ? fixed.after : fixed.before;
  std::printf("held-out 1-step RMSE (%ld rows)   %-10s %11s %11s %11s   LB p before/after\n", fixed.before.samples,
              "channel", "before", "fine-tune", "after");
  // A figure that was not computed (a new channel has no "before"; nothing
  // fixed has no "after"; --no-control has no fine-tune) prints as "-".
  const auto cell = [](bool computed, double v, const char* format) {
    if (!computed) return std::string("-");
    char buf[32];
    std::snprintf(buf, sizeof buf, format, v);
    return std::string(buf);
  };
  for (std::size_t c = 0; c < e.channels.size(); ++c) {
    const auto i = static_cast<Eigen::Index>(c);
    const bool old = c < fixed.before.channels.size();
    const bool control = fixed.control.has_value() && old;
    std::printf("                                  %-10s %11s %11s %11s   %s / %s\n", e.channels[c].c_str(),
                cell(old, old ? fixed.before.rmse(i) : 0, "%.4g").c_str(),
                cell(control, control ? fixed.control->rmse(i) : 0, "%.4g").c_str(),
                cell(fixed.tried, fixed.tried ? fixed.after.rmse(i) : 0, "%.4g").c_str(),
                cell(old, old ? fixed.before.whiteness[c].ljung_box.p_value : 0, "%.2g").c_str(),
                cell(fixed.tried, fixed.tried ? fixed.after.whiteness[c].ljung_box.p_value : 0, "%.2g").c_str());
  }
  if (fixed.tried) {
    std::printf("decision: against %s on", fixed.reference.c_str());
    for (const auto& c : fixed.confirmation_channels) std::printf(" %s", c.c_str());
    std::printf(": Diebold-Mariano p %.2g", fixed.confirmation.p_value);
    if (fixed.folds > 1) std::printf(" (%d folds; the first alone: p %.2g)", fixed.folds, fixed.first_fold.p_value);
    std::printf(", each channel in %s", fixed.scale == rs::DecisionScale::kResidual ? "its clean residual level"
                                                                                     : "its standard deviation");
    if (fixed.own_channels)
      std::printf("; on its own channels mean loss difference %.3g", fixed.own_channels->mean);
    std::printf(": %s\n", fixed.changed ? "confirmed" : "not confirmed, nothing applied");
    if (fixed.simpler) std::printf("%s\n", simpler_sentence(*fixed.simpler, fixed.reference).c_str());
    if (fixed.rivals) std::printf("%s\n", rivals_sentence(*fixed.rivals, fixed.reference).c_str());
    if (fixed.richer) std::printf("%s\n", richer_sentence(*fixed.richer, fixed.reference).c_str());
    for (const auto& wider : fixed.extensions) std::printf("%s\n", extension_sentence(wider).c_str());
    if (replaced_after_decision(fixed)) std::printf("the before/after above are the plan applied last\n");
    if (!fixed.folds_note.empty()) std::printf("note: %s\n", fixed.folds_note.c_str());
    if (!fixed.scale_note.empty()) std::printf("note: %s\n", fixed.scale_note.c_str());
  }
  // The selection's candidates, also when it tested none (no gain, no decision).
  if (fixed.candidates.size() > 1 && (fixed.tried || fixed.none_gained)) {
    std::printf("candidates (the screen's order; * the one tested: the first whose gain over fine-tuning alone\n"
                "on the training rows' last 25 %% is significant, else the clearest gain; none when none gains;\n"
                "a load drift gives way to the drift probe's plan of its group when that plan gains there too\n"
                "and predicts the channels either changes better there):\n");
    for (const auto& c : fixed.candidates) {
      std::printf("  %c %-74.74s", c.chosen ? '*' : ' ', (c.effect + ": " + c.description).c_str());
      if (c.below_screen_floor) std::printf(" below the screen's floor (%.2g);", c.screen_statistic);
      if (c.from_drift_probe) std::printf(" the drift probe's;");
      if (c.from_earlier_round) std::printf(" an earlier round's;");
      if (c.rail_of_chosen_curve) std::printf(" the chosen curve's rail;");
      if (c.group_drift_gain)
        std::printf(" the drift probe's plan of its group %s (DM %.2f);",
                    c.gave_way_to_group_drift ? "predicts better: gave way" : "not preferred", c.group_drift_gain->stat);
      if (c.selected_by_training_rows)
        std::printf(" training rows: DM %.2f, p %.2g\n", c.selection.stat, c.selection.p_value);
      else std::printf(" not judged\n");
    }
  }
  if (fixed.tried) std::printf("verdict after: %s\n", fixed.after.verdict.c_str());
}

// The value of the named option --`name` that `named` reads (one of
// `values`, as the error message lists them); none after printing the error.
template <class Named>
auto named_value(const Options& opt, const char* name, Named named, const char* values) {
  auto value = named(opt.get(name));
  if (!value)
    std::fprintf(stderr, "hadynet residual: --%s is %s, not '%s'\n", name, values, opt.get(name).c_str());
  return value;
}

}  // namespace

int run_residual(int argc, char** argv) {
  Options opt("residual",
              "The model's residual over logs and what it lacks (docs/residual.md): multi-step fit and RMSE per\n"
              "channel and horizon, whiteness (autocorrelation, Ljung-Box) and independence (cross-correlation\n"
              "with the inputs) of the 1-step residual, and the effect library's hypotheses (sensor and input\n"
              "delay, friction/hysteresis, drift, saturation, a static calibration curve, cross-talk, unused aux_*\n"
              "channels) fitted on the first part of each log and tested on the rest. Prints the winner with its\n"
              "parameters, or 'no significant effect'. Works on any (u, y) logs the model's channels fit.",
              "MODEL LOG|DIR... [options]");
  opt.value("pb", "PB",
            "auto (the state's trained PB if the model knows it and it predicts a typical channel of the\n"
            "state's held-out rows (geometric mean over the channels) at most " + num("%g", rs::kStoredPbMargin) +
                " times worse than one\nadapted to its other rows, else adapted), state, adapt, zero, a state,\n"
                "or values",
            "auto");
  opt.value("horizon", "N", "multi-step horizon (default: the model's N_train)");
  opt.value("max-lag", "L", "correlation lags 1..L (whiteness) and -L..L (independence)",
            std::to_string(rs::kDefaultMaxLag));
  opt.value("max-delay", "D", "delays tested: 1..D steps", "5");
  opt.value("train-fraction", "F", "part of each log (from its start) the hypotheses are fitted on", "0.6");
  opt.value("alpha", "A", "family-wise error rate of the Holm-corrected tests", "0.01");
  opt.value("min-explained", "S", "floor: share of the held-out residual variance an effect must explain", "0.1");
  opt.value("min-explained-std", "V",
            "floor without a null: held-out explained variance in standardised units (drop of the channel's\n"
            "1-step loss; the default was set on the hand's models)", "0.05");
  opt.repeated("reference", "LOG|DIR|none",
               "clean logs of the same channels for a calibrated null: neither the model's training logs nor the\n"
               "logs under test (e.g. validation logs recorded with them). Every hypothesis is also tested there;\n"
               "an effect must then explain more than on the null by --min-excess-null times its channel's clean\n"
               "residual level (replacing --min-explained-std), so the floors follow the model's own scale.\n"
               "Default: the held-out logs stored in the model by train (its training logs' held-out rows; any\n"
               "whose rows are in a log under test is left out); none: no null, absolute floors");
  opt.value("min-excess-null", "S", "with a null: how many times its channel's clean residual level an effect must\n"
                                     "explain beyond the null", num("%g", rs::kDefaultMinExcessNull));
  opt.value("absolute-inputs", "GROUPS",
            "command groups whose commands are levels (a position or voltage set point), not motions, e.g. u:\n"
            "friction then follows their change (default: the logs' absolute_groups metadata; none: no group)");
  opt.value("crosstalk-sources", "unit|group|all",
            "cross-talk sources of a channel: the other channels of its group and those of any group\n"
            "measured in its unit (the logs' `units` metadata) (unit), its group only (group), or every\n"
            "other observed channel (all)",
            "unit");
  opt.repeated("rated-range", "NAME=LOW..HIGH",
               "a sensor's rated range (datasheet) for an output group or channel, e.g. fc=0..50: the predictions\n"
               "are clipped there as known before anything is searched (a rail there is not an effect), and a\n"
               "calibration curve --fix fits ends at HIGH reading HIGH (unless its fit ends flat where the group's\n"
               "channels top out together: a rail's signature); either bound may be left out (f=0..)");
  opt.value("report", "DIR", "write DIR/REPORT.md with PNG plots (gnuplot) and DIR/residual.json");
  opt.value("json", "FILE", "write every number as JSON");
  opt.flag("fix", "add the winning effect (sensor delay: time alignment, or the commands' dead time when the delay\n"
                  "shows on other groups too; cross-talk: removal; drift: a bias state;\n"
                  "saturation: clipping; sensor curve: a calibration curve; friction: hysteresis inputs; input\n"
                  "delay: the commands d steps earlier as inputs; aux channel: an observed channel), fine-tune\n"
                  "on the first --train-fraction of each log and report before/after on the rest; the effect is\n"
                  "confirmed (and the model kept) only when it beats fine-tuning alone on the held-out rows of\n"
                  "the channels it changes (one-sided Diebold-Mariano test at --alpha; with --fix-folds 2 also on\n"
                  "the mirrored fold's), else 'unexplained structure'");
  opt.value("rounds", "N",
            "with --fix: repeat analysis and fix until nothing is confirmed, at most N rounds (so that two\n"
            "effects at once are both found); the next round analyses the confirmed change on the network\n"
            "before fine-tuning when the change alone describes the effect (sensor changes, an input dead\n"
            "time), else the fine-tuned model, and also tries the candidates the rounds before proposed\n"
            "and did not apply; the reference logs are read through the sensors they were recorded with\n"
            "in every round; round k > 1 reports into DIR/round-k", "1");
  opt.value("out", "FILE", "with --fix: write the augmented model of the last confirmed round (only when\n"
                           "something was fixed)");
  opt.value("fix-epochs", "N", "with --fix: fine-tuning epochs", "20");
  opt.value("fix-lr", "X", "with --fix: Adam learning rate", "0.001");
  opt.value("fix-seed", "N", "with --fix: seed of the window order", "1");
  opt.value("candidates", "K", "with --fix: how many of the screen's candidates may be tried (the best of each effect;\n"
                              "a delay, curve, rail or cross-talk extended to its group also on its family alone,\n"
                              "right after):\n"
                              "each added, fine-tuned on the first 75 % of the training rows and compared with\n"
                              "fine-tuning alone on the rest; the first significant there, else the clearest gain,\n"
                              "is the one the decision tests on the held-out rows, none when none gains (1: the\n"
                              "screen's winner); a confirmed calibration curve gives way to a rail planned on its lead\n"
                              "channel (else on another channel the curve was found on) when the rail is confirmed\n"
                              "itself and the curve does not predict the channels either claims significantly better\n"
                              "(the simpler account; a confirmed friction gives way likewise to a calibration curve of\n"
                              "its lead channel, else of another channel it was found on); a confirmed cross-talk\n"
                              "within a group gives way to a calibration curve of its target's group only when the\n"
                              "curve is confirmed itself and predicts the channels either claims significantly better\n"
                              "(the richer account); a family alone confirmed is\n"
                              "then extended to its group when the extended plan predicts the channels it adds\n"
                              "significantly better on the held-out rows, and a delay seen beyond its family likewise\n"
                              "to every channel of its group; the drift probe asks each channel group whether a load\n"
                              "drift at one rate, fitted on the first 75 % of the training rows, makes the unchanged\n"
                              "network predict the rest better (one-sided Diebold-Mariano, Holm over the groups), and\n"
                              "each group that does is one more candidate, the smallest p first (after the screen's\n"
                              "drift of its group, one holding a channel of it, beyond K, when it lists one; else last,\n"
                              "beyond K when every place is taken); a load drift of its group chosen on the training\n"
                              "rows gives way to it when it gains there\n"
                              "too and predicts the channels either changes better there; the rivals of a chosen\n"
                              "calibration curve (the other effects of its group; when its group tops out together, a\n"
                              "rail's signature, also the rail of its lead channel), drift with time (the load drifts of its\n"
                              "group) or load drift (the curves and drifts with time of its groups), and of either drift\n"
                              "the drift probe's plans of any group, cross-talk within a group (the curves and load\n"
                              "drifts of its group) or friction (the curves of its groups), and of any choice every\n"
                              "plan of the groups it does not hold that gained more than it, that gained on those rows\n"
                              "too are tested beside it on the held-out rows, all at Holm's levels, and of those\n"
                              "confirmed the one --fix-tie-break picks is applied (by default, of the best predictor\n"
                              "of the channels any of them changes and the plans it does not beat significantly there,\n"
                              "the one changing the fewest channels)", "5");
  opt.value("fix-min-excess-null", "S",
            "with --fix and a null: the candidates --fix may try reach down to S times their channel's clean\n"
            "residual level beyond the null, below the screen's --min-excess-null (the verdict's floor); the\n"
            "decision on held-out rows against fine-tuning alone guards what is applied\n"
            "(docs/residual-experiments.md, \"Candidates down to 1 by default\"); never above\n"
            "--min-excess-null",
            num("%g", rs::kDefaultFixMinExcessNull));
  opt.value("fix-upper-rail-floor", "S",
            "with --fix and a null: an upper rail (the readings of a channel clipped at their top) is a\n"
            "candidate down to S times its channel's clean residual level beyond the null, below the\n"
            "candidates' floor (--fix-min-excess-null), when the screen finds it at Holm's level with its\n"
            "share of the held-out residual variance and a plausible gain (docs/residual-experiments.md,\n"
            "\"An upper rail below the candidates' floor\"); never above the candidates' floor",
            num("%g", rs::kDefaultFixUpperRailFloor));
  opt.value("drift-probe-alpha", "A",
            "with --fix: the drift probe's family-wise level (Holm over the channel groups whose fitted rate\n"
            "is positive; see --candidates); 0: no probe",
            num("%g", rs::kDefaultDriftProbeAlpha));
  opt.value("fix-folds", "1|2",
            "with --fix: 2 also judges a mirrored fold (the candidate and its reference fine-tuned on each\n"
            "log's last rows, judged on the rows before them), pooled with the first fold in the decision's\n"
            "test (not when --train-fraction is below 4/7 or a log is too short); 1: the first fold alone\n"
            "(the written model and the before/after columns are the first fold's either way)", "2");
  opt.value("decision-loss", "squared|absolute",
            "with --fix: the per-row loss of its Diebold-Mariano tests (the selection, the decision, the tests\n"
            "after it, the drift probe): the mean over the judged channels of the standardised 1-step error,\n"
            "squared or absolute (lighter-tailed differences on contact-rich logs, but it confirmed curves on\n"
            "clean logs: docs/residual-experiments.md, \"The decision's loss\", \"Back to the squared\n"
            "loss\")",
            rs::decision_loss_name(rs::FixOptions{}.decision_loss));
  opt.value("fix-selection", "screen-order|every-channel",
            "with --fix: how the candidates are compared on the training rows: screen-order (each on its own\n"
            "channels, the first in the screen's order that gains significantly) or every-channel (each on\n"
            "every channel, the largest statistic among those that gain significantly)",
            rs::selection_rule_name(rs::FixOptions{}.selection));
  opt.value("fix-tie-break", "largest-gain|fewest-channels",
            "with --fix: which plan is applied when two or more of the choice and its rivals are confirmed:\n"
            "largest-gain (the largest mean gain on the channels any of them changes) or fewest-channels\n"
            "(of that plan and the plans it does not beat significantly there, the one changing the\n"
            "fewest channels)",
            rs::tie_break_name(rs::FixOptions{}.tie_break));
  opt.value("decision-scale", "std|residual",
            "with --fix: the unit of each channel's error in the held-out tests' loss (the decision and\n"
            "the tests after it; the selection and the drift probe keep std) before the mean over the judged\n"
            "channels: std (its standard deviation: channels the model predicts worse weigh more) or residual\n"
            "(also divided by its clean 1-step residual level on the null, the floors' unit: each channel's\n"
            "relative change counts alike; needs a null, else std is used and said)",
            rs::decision_scale_name(rs::FixOptions{}.decision_scale));
  opt.value("decision-pooling", "rows|logs",
            "with --fix: how the held-out tests pool the logs' per-row losses: rows (every row as it comes:\n"
            "a log with larger errors weighs more) or logs (each log of each fold divided by its mean loss of\n"
            "the two models compared first: every log counts by its relative difference;\n"
            "docs/residual-experiments.md, \"Each log in its own level\")",
            rs::decision_pooling_name(rs::FixOptions{}.decision_pooling));
  opt.flag("no-control", "with --fix: skip the fine-tune-only comparison (the decision then compares with the\n"
                        "unchanged model, a weaker guard)");
  add_threads_option(opt, "1");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (opt.positional().size() < 2) {
    std::fprintf(stderr, "hadynet residual: give MODEL and logs (see --help)\n");
    return 2;
  }
  if (!apply_threads_option(opt, "residual")) return 2;
  const auto max_lag = opt.get_int("max-lag", 1, 1000);
  const auto max_delay = opt.get_int("max-delay", 1, 100);
  const auto fraction = opt.get_double("train-fraction", 0.1, 0.9);
  const auto alpha = opt.get_double("alpha", 1e-12, 0.5);
  const auto min_share = opt.get_double("min-explained", 0.0, 1.0);
  const auto min_std = opt.get_double("min-explained-std", 0.0, 1e6);
  const auto min_excess = opt.get_double("min-excess-null", 0.0, 1e6);
  std::optional<long long> horizon;
  if (opt.has("horizon")) {
    horizon = opt.get_int("horizon", 1, 1000);
    if (!horizon) return 2;
  }
  if (!max_lag || !max_delay || !fraction || !alpha || !min_share || !min_std || !min_excess) return 2;
  const std::vector<std::string> reference_args = opt.all("reference");
  const bool no_reference = reference_args.size() == 1 && reference_args.front() == "none";
  if (opt.has("min-excess-null") && no_reference) {
    std::fprintf(stderr, "hadynet residual: --min-excess-null needs a null (not --reference none)\n");
    return 2;
  }
  const std::string crosstalk_sources = opt.get("crosstalk-sources");
  if (crosstalk_sources != "unit" && crosstalk_sources != "group" && crosstalk_sources != "all") {
    std::fprintf(stderr, "hadynet residual: --crosstalk-sources must be unit, group or all, not '%s'\n",
                 crosstalk_sources.c_str());
    return 2;
  }
  std::optional<std::vector<std::string>> absolute_groups;
  if (opt.has("absolute-inputs")) {
    try {
      absolute_groups = datalog::split_list(opt.get("absolute-inputs"));
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "hadynet residual: --absolute-inputs: %s\n", e.what());
      return 2;
    }
  }
  const auto fix_epochs = opt.get_int("fix-epochs", 1, 100000);
  const auto fix_lr = opt.get_double("fix-lr", 1e-12, 10.0);
  const auto fix_seed = opt.get_int("fix-seed", 0, (1ll << 62));
  const auto rounds = opt.get_int("rounds", 1, 20);
  const auto candidates = opt.get_int("candidates", 1, 20);
  const auto folds = opt.get_int("fix-folds", 1, 2);
  const auto drift_probe_alpha = opt.get_double("drift-probe-alpha", 0.0, 0.5);
  const auto decision_loss = named_value(opt, "decision-loss", rs::decision_loss_named, "squared or absolute");
  if (!decision_loss) return 2;
  const auto decision_scale = named_value(opt, "decision-scale", rs::decision_scale_named, "std or residual");
  if (!decision_scale) return 2;
  const auto decision_pooling = named_value(opt, "decision-pooling", rs::decision_pooling_named, "rows or logs");
  if (!decision_pooling) return 2;
  const auto selection = named_value(opt, "fix-selection", rs::selection_rule_named, "screen-order or every-channel");
  if (!selection) return 2;
  const auto tie_break = named_value(opt, "fix-tie-break", rs::tie_break_named, "largest-gain or fewest-channels");
  if (!tie_break) return 2;
  std::optional<double> fix_min_excess;  // given; else FixOptions' default (fix() keeps it at most the screen's)
  if (opt.has("fix-min-excess-null")) {
    fix_min_excess = opt.get_double("fix-min-excess-null", 0.0, 1e6);
    if (!fix_min_excess) return 2;
  }
  std::optional<double> fix_upper_rail_floor;  // given; else FixOptions' default
  if (opt.has("fix-upper-rail-floor")) {
    fix_upper_rail_floor = opt.get_double("fix-upper-rail-floor", 0.0, 1e6);
    if (!fix_upper_rail_floor) return 2;
  }
  if (!fix_epochs || !fix_lr || !fix_seed || !rounds || !candidates || !folds || !drift_probe_alpha) return 2;
  if (opt.has("fix-min-excess-null") && !opt.has("fix")) {
    std::fprintf(stderr, "hadynet residual: --fix-min-excess-null needs --fix\n");
    return 2;
  }
  if (fix_min_excess && *fix_min_excess > *min_excess) {
    std::fprintf(stderr, "hadynet residual: --fix-min-excess-null %g is above the screen's --min-excess-null %g: the\n"
                 "candidates' floor can only be lower\n", *fix_min_excess, *min_excess);
    return 2;
  }
  if (opt.has("fix-min-excess-null") && no_reference) {
    std::fprintf(stderr, "hadynet residual: --fix-min-excess-null needs a null (not --reference none)\n");
    return 2;
  }
  if (opt.has("fix-upper-rail-floor") && !opt.has("fix")) {
    std::fprintf(stderr, "hadynet residual: --fix-upper-rail-floor needs --fix\n");
    return 2;
  }
  if (opt.has("fix-upper-rail-floor") && no_reference) {
    std::fprintf(stderr, "hadynet residual: --fix-upper-rail-floor needs a null (not --reference none)\n");
    return 2;
  }
  if (const double candidates_floor = fix_min_excess ? *fix_min_excess : std::min(rs::kDefaultFixMinExcessNull, *min_excess);
      fix_upper_rail_floor && *fix_upper_rail_floor > candidates_floor) {
    std::fprintf(stderr, "hadynet residual: --fix-upper-rail-floor %g is above the candidates' floor %g\n"
                 "(--fix-min-excess-null, at most --min-excess-null): an upper rail's floor can only be lower\n",
                 *fix_upper_rail_floor, candidates_floor);
    return 2;
  }
  if (opt.has("drift-probe-alpha") && !opt.has("fix")) {
    std::fprintf(stderr, "hadynet residual: --drift-probe-alpha needs --fix\n");
    return 2;
  }
  if (opt.has("rounds") && !opt.has("fix")) {
    std::fprintf(stderr, "hadynet residual: --rounds needs --fix\n");
    return 2;
  }
  if (opt.has("out") && !opt.has("fix")) {
    std::fprintf(stderr, "hadynet residual: --out needs --fix\n");
    return 2;
  }

  std::vector<rs::RatedRange> rated_ranges;
  try {
    for (const auto& text : opt.all("rated-range")) rated_ranges.push_back(rs::parse_rated_range(text));
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "hadynet residual: --rated-range: %s\n", e.what());
    return 2;
  }

  try {
    const std::string model_path = opt.positional().front();
    std::vector<trainer::OutputClip> known_clips;
    const trainer::HadynetModel model = rs::with_rated_ranges(trainer::load_model(model_path), rated_ranges, &known_clips);
    if (!known_clips.empty()) {
      std::printf("rated ranges: the predictions are clipped as known at");
      for (const auto& c : known_clips) std::printf(" %s %s %g;", c.channel.c_str(), c.side > 0 ? "<=" : ">=", c.rail);
      std::printf(" no rail there is searched for\n");
    }
    const std::vector<std::string> args(opt.positional().begin() + 1, opt.positional().end());
    std::vector<rs::LogInput> inputs;
    for (const auto& path : trainer::expand_log_paths(args)) inputs.push_back({datalog::read_log(path), path});
    std::string null_source;
    const std::vector<rs::LogInput> reference =
        no_reference ? std::vector<rs::LogInput>{}
                     : reference_logs(model, model_path, reference_args, inputs, &null_source);
    if (no_reference) null_source = "--reference none";
    for (const char* name : {"min-excess-null", "fix-min-excess-null"}) {
      if (opt.has(name) && reference.empty()) {
        std::fprintf(stderr, "hadynet residual: --%s needs a null: %s\n", name, null_source.c_str());
        return 2;
      }
    }

    rs::AnalysisOptions ao;
    ao.pb_choice = opt.get("pb");
    ao.horizon = horizon ? static_cast<int>(*horizon) : 0;
    ao.max_lag = static_cast<int>(*max_lag);
    ao.library.max_delay = static_cast<int>(*max_delay);
    ao.library.absolute_groups = absolute_groups;
    ao.library.crosstalk_sources = crosstalk_sources == "group" ? rs::CrosstalkSources::kSameGroup
                                   : crosstalk_sources == "all" ? rs::CrosstalkSources::kAll
                                                                : rs::CrosstalkSources::kSameUnit;
    ao.attribution.train_fraction = *fraction;
    ao.attribution.alpha = *alpha;
    ao.attribution.min_explained = *min_share;
    ao.attribution.min_explained_std = *min_std;
    ao.attribution.min_excess_null = *min_excess;
    ao.null_source = null_source;
    // The stored held-out logs are the trained states' own rows: their trained PBs.
    const bool stored_null = !no_reference && reference_args.empty() && !reference.empty();
    ao.reference_pb_choice = stored_null ? "state" : "";
    const std::string& pb_choice = ao.pb_choice;
    rs::FixOptions fo;
    fo.train_fraction = *fraction;
    fo.rated_ranges = rated_ranges;
    fo.epochs = static_cast<int>(*fix_epochs);
    fo.lr = *fix_lr;
    fo.seed = static_cast<std::uint64_t>(*fix_seed);
    fo.control = !opt.has("no-control");
    fo.candidates = static_cast<int>(*candidates);
    fo.drift_probe_alpha = *drift_probe_alpha;
    fo.folds = static_cast<int>(*folds);
    fo.decision_loss = *decision_loss;
    fo.decision_scale = *decision_scale;
    fo.decision_pooling = *decision_pooling;
    fo.selection = *selection;
    fo.tie_break = *tie_break;
    if (fix_min_excess) fo.min_excess_null = fix_min_excess;
    if (fix_upper_rail_floor) fo.upper_rail_floor = fix_upper_rail_floor;
    fo.reference = &reference;
    fo.reference_pb_choice = stored_null ? "state" : "auto";
    fo.library = ao.library;
    // The sensors the reference logs were recorded through, in every round:
    // the stored held-out logs are rows of the training logs, which `train`
    // models without a sensor model (a later --fix changes the model's sensor
    // model, not those logs), so only the clips (rated ranges, rails) apply;
    // --reference logs are read through the input model's sensor model.
    trainer::SensorModel reference_sensor = model.sensor;
    if (stored_null) {
      reference_sensor = {};
      reference_sensor.clips = model.sensor.clips;
    }
    ao.reference_sensor = &reference_sensor;
    fo.reference_sensor = &reference_sensor;

    // Rounds: each analyses `current` and fixes when asked; the loop ends at
    // the first round that confirms nothing. `current` after a confirmed round
    // is its change on the network before fine-tuning when the change alone
    // carries its effect (Augmentation::carried_before_tuning: fine-tuning on
    // these logs would absorb part of a second effect before it is looked
    // for), else the fine-tuned model. Round 1 reports into --report DIR and
    // --json FILE; round k > 1 into DIR/round-k and the JSON's "rounds". --out
    // holds the last confirmed round's model, which carries every earlier
    // round's change.
    json rounds_json = json::array();
    auto write_json = [](const json& j, const std::string& path) {
      std::ofstream out(path);
      if (!out) throw std::runtime_error(path + ": cannot write");
      out << j.dump(1) << '\n';
      if (!out) throw std::runtime_error(path + ": write failed");
      std::fflush(stdout);  // the report's lines whole before this one, when both go to one file
      std::fprintf(stderr, "wrote %s\n", path.c_str());
    };
    trainer::HadynetModel current = model;
    std::string current_path = model_path;
    std::string written;
    std::string current_what;  // what `current` is from round 2 on, in words
    int confirmed_rounds = 0;
    std::vector<std::string> confirmed_effects;
    // The next round also tries what the rounds before proposed and did not
    // apply (FixOptions::earlier_candidates), of no effect confirmed yet.
    std::vector<std::string> confirmed_kinds;
    std::vector<rs::Augmentation> earlier_candidates;
    fo.earlier_candidates = &earlier_candidates;
    const int round_count = opt.has("fix") ? static_cast<int>(*rounds) : 1;
    json first_json;
    for (int round = 1; round <= round_count; ++round) {
      if (round > 1) std::printf("\n=== round %d: on the same logs, %s ===\n", round, current_what.c_str());
      const rs::Analysis a = rs::analyse(current, inputs, ao, reference);
      print_summary(a, pb_choice, opt.has("fix"));
      json j = analysis_json(a, current_path, pb_choice);
      j["rated_ranges"] = opt.all("rated-range");
      j["reference"] = opt.all("reference");
      j["null_source"] = null_source;
      std::optional<rs::FixResult> fixed;
      std::string round_written;
      if (opt.has("fix")) {
        fixed = rs::fix(current, inputs, a.data, a.attribution, fo);
        print_fix(*fixed);
        j["fix"] = fix_json(*fixed, fo);
        if (fixed->changed) {
          ++confirmed_rounds;
          confirmed_effects.push_back(fixed->augmentation->description);
          if (opt.has("out")) {
            round_written = opt.get("out");
            trainer::save_model(round_written, fixed->model);
            std::fflush(stdout);
            std::fprintf(stderr, "wrote %s (round %d)\n", round_written.c_str(), round);
            j["fix"]["model"] = round_written;
            written = round_written;
          }
        }
      }
      j["round"] = round;
      if (opt.has("report")) {
        std::filesystem::path dir = opt.get("report");
        if (round > 1) dir /= "round-" + std::to_string(round);
        std::filesystem::create_directories(dir);
        write_json(j, (dir / "residual.json").string());
        write_report(dir, a, current_path, pb_choice, fixed ? &*fixed : nullptr, fo, round_written);
      }
      if (round == 1) first_json = j;
      else rounds_json.push_back(j);
      if (!fixed || !fixed->changed) break;
      confirmed_kinds.push_back(fixed->augmentation->effect);
      earlier_candidates = rs::earlier_candidates_for_next_round(*fixed, confirmed_kinds);
      // Without a control the next round's reference is its own input model:
      // it must be the fine-tuned one (else fine-tuning alone would count as the fix's gain).
      const bool untuned = fo.control && fixed->augmentation->carried_before_tuning();
      current = untuned ? fixed->untuned : fixed->model;
      current_what = untuned ? "the change of round " + std::to_string(round) +
                                   " on the network before its fine-tuning (the change alone carries the effect)"
                             : "the model fixed in round " + std::to_string(round);
      current_path = untuned          ? "(round " + std::to_string(round) + "'s change before fine-tuning, not written)"
                     : written.empty() ? "(the model of round " + std::to_string(round) + ", not written)"
                                       : written;
      if (round == round_count && round_count > 1)
        std::printf("\n--rounds %d reached with the last round confirmed: more may remain\n", round_count);
    }
    if (opt.has("fix") && round_count > 1) {
      std::printf("\nrounds: %d confirmed", confirmed_rounds);
      for (const auto& e : confirmed_effects) std::printf("; %s", e.c_str());
      std::printf("\n");
      first_json["rounds"] = rounds_json;
    }
    if (opt.has("out") && written.empty()) std::fprintf(stderr, "nothing fixed: %s not written\n", opt.get("out").c_str());
    if (opt.has("json")) write_json(first_json, opt.get("json"));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet residual: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
