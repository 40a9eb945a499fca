// The margins of the `hadynet residual --fix` tests: their one source.
// fix_test.cc and generic_layout_test.cc take every bound from here, and
// FixMargins.DocsTableIsThisTable (fix_margins_test.cc) checks that the
// "Test margins" table of docs/residual.md is margins_table() below, so the
// docs cannot drift from the tests.
//
// Each bound is stated with the value measured when it was set (release
// build, 2 threads, the tests' seeds: 20 epochs from the build's model, seed
// 1, the first 60 % of each log's rows) and, in `why`, why it is where it is.
// What every ratio bound shares: "after / before" and "after / fine-tune
// only" are held-out 1-step RMSE ratios of one channel; each bound sits
// between the measured value and 1 (no gain), with room for thread-count
// rounding (the CLI reproduces the numbers to about 1 %), and tight enough
// that losing the effect's mechanism fails it. They are not derived from a
// noise model.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

namespace hadynet::test::fix_margins {

// value < limit
struct Below {
  double limit;
  double measured;
};
// value > limit
struct Above {
  double limit;
  double measured;
};
// lo < value < hi
struct Between {
  double lo, hi;
  double measured;
};

// Plant: every loadcell reported 2 steps late (sensor-delay=2).
struct SensorDelay {
  Below winner_vs_before;   // the winner (fc1): after / before
  Below winner_vs_control;  // the winner: after / fine-tune only
  Below aligned_vs_before;  // every aligned channel: after / before (measured: the worst, fc5)
  Below aligned_median;     // the median of after / before over the aligned channels
  int delay_steps;          // the plant's delay, found on
  int aligned_channels;     // every loadcell
  const char* why;
};
inline constexpr SensorDelay kSensorDelay{
    .winner_vs_before = {0.6, 0.36},
    .winner_vs_control = {0.6, 0.45},
    .aligned_vs_before = {0.97, 0.93},
    .aligned_median = {0.75, 0.61},
    .delay_steps = 2,
    .aligned_channels = 9,
    .why = "the cut must be the alignment's, so the bound against fine-tuning alone is as tight as against "
           "before; every aligned channel must gain (fc5 barely moves in these grasps: 0.93), which catches "
           "aligning only the channels past the floors (five delayed loadcells got worse, up to 1.4×)"};

// A fix that adds inputs for the winner's family: its cut on the winner,
// against fine-tuning alone there, and on every family channel (measured:
// the worst).
struct FamilyCut {
  Below winner_vs_before;
  Below winner_vs_control;
  Below family_vs_before;
  const char* why;
};

// Plant: 4 N of dry friction on every tendon (friction). Winner f0; the
// family's worst f1.
inline constexpr FamilyCut kFriction{
    .winner_vs_before = {0.75, 0.61},
    .winner_vs_control = {0.95, 0.87},
    .family_vs_before = {0.9, 0.76},
    .why = "fine-tuning alone already cuts f0 to 0.70×, so the hysteresis inputs are asked for a further 5 %; "
           "the family channels measured 0.58-0.76×"};

// Plant: the servos act on every command 2 steps late (input-delay). Winner
// l5; the family: the channels the delay was found on.
inline constexpr FamilyCut kInputDelay{
    .winner_vs_before = {0.45, 0.30},
    .winner_vs_control = {0.5, 0.35},
    .family_vs_before = {0.55, 0.46},
    .why = "against the model's stored null, as `hadynet residual` by default (with absolute floors a fingertip "
           "cross-talk pair ranks first); fine-tuning alone cuts l5 to 0.86×; the lag inputs start as the pure "
           "dead time (the commands' weights moved to them), and the bounds fail the start at zero weights, "
           "which measured 0.57× before and 0.66× the control; the family channels measured 0.30-0.46× (with the "
           "candidates' floor of 1, the default since stop 48, the family has the loadcells and tendons f3-f5 too: "
           "f4 is cut least)"};

// Plant: every loadcell reads 50 N (F / 50 N)^0.85 (sensor-curve). Winner
// fc3; the family: the loadcells with a curve.
struct SensorCurve {
  Below winner_vs_before;
  Below winner_vs_control;
  Below family_vs_before;
  Below winner_reading_error;  // |fitted - plant| / plant at the winner's highest knot
  const char* why;
};
inline constexpr SensorCurve kSensorCurve{
    .winner_vs_before = {0.5, 0.44},
    .winner_vs_control = {1.1, 1.004},
    .family_vs_before = {0.95, 0.90},
    .winner_reading_error = {0.15, 0.095},
    .why = "against the model's stored null, as `hadynet residual` by default; fine-tuning alone cuts fc3 to "
           "0.44×, and the identity curve (no fit) would leave the control's error (1.0×) and read 26 % low at "
           "the top knot; since stop 57 one curve for the six loadcells (a curve per channel read 22 % low, "
           "and measured 0.37× before and 0.85× the control); since stop 74 the curve bends one way "
           "(compressive): it reads 9.5 % above the plant's at the top knot (0.1 % before), fc3 measures "
           "1.004× fine-tuning alone's (0.85×) on these logs of the model's training seed, where fine-tuning "
           "alone does best, and the family channels 0.69-0.90× before (fc5 the worst; 0.62-0.82×); on fresh "
           "curve sets the shape names 10 of 20 against 7 (docs/residual-experiments.md, \"A curve that bends one way\")"};

// Plant: fingertip loadcell i adds 0.35 x its neighbour's force (crosstalk).
struct Crosstalk {
  Below winner_vs_before;   // the target (fc2)
  Below winner_vs_control;
  Below further_vs_before;  // the group's further pair's target (fc0)
  Below further_vs_control;
  Between gain;             // the fitted gain removed (each pair's)
  Above target_ljung_box_p;  // the target's held-out residual after the fix
  const char* why;
};
inline constexpr Crosstalk kCrosstalk{
    .winner_vs_before = {0.6, 0.46},
    .winner_vs_control = {0.95, 0.90},
    .further_vs_before = {0.6, 0.39},
    .further_vs_control = {0.9, 0.72},
    .gain = {0.1, 0.5, 0.250},
    .target_ljung_box_p = {1e-3, 0.097},
    .why = "the source fc3 is an input, so fine-tuning alone learns most of the pick-up (0.51× before) and the "
           "bound against it is loose; the fitted gain is below the plant's 0.35 (persistence, docs above); "
           "the removal leaves the target nearly white (p 1e-78 before); since stop 60 the group's further "
           "pair fc1 → fc0 is removed with it (fine-tuning alone cuts fc0 to 0.54×, so its bound against "
           "before is loose too)"};

// Plant: loadcell bias growing 0.02 N per N s of load (drift=0.02, 5× the default).
struct Drift {
  Below winner_vs_before;   // the winner (fc3)
  Below winner_vs_control;
  Between rate_vs_plant;    // the re-estimated rate (one for the group) / the plant's 0.02
  Below family_vs_before;   // every channel the test found it on (measured: the worst, fc6)
  Below each_vs_control;    // the whole group's plan: every loadcell / fine-tuning alone (the worst, fc5)
  Below group_vs_control;   // the whole group's plan: summed loadcell RMSE / fine-tuning alone's
  const char* why;
};
inline constexpr Drift kDrift{
    .winner_vs_before = {0.5, 0.25},
    .winner_vs_control = {0.75, 0.41},
    .rate_vs_plant = {0.7, 1.3, 0.936},
    .family_vs_before = {0.8, 0.48},
    .each_vs_control = {1.0, 0.88},
    .group_vs_control = {0.85, 0.70},
    .why = "the attribution's own fit of the rate is 0.42× the plant's, so the rate bound fails when the "
           "re-estimation does not run; since stop 55 the rate is the group's, re-estimated on the nine "
           "loadcells' summed 1-step MSE (stop 54 re-estimated it on fc3 alone: 1.384, with the bound widened to "
           "0.7–1.5); since stop 56 the selection takes the drift probe's plan on all nine (training rows p 6e-5) "
           "over the screen's drift of fc3 and fc6 (p 0.3), which stop 55 confirmed and then extended to the "
           "nine at 0.895×; the bias state must cut well beyond fine-tuning alone, on every loadcell (lightly "
           "loaded ones barely drift: fc5 0.88), and the nine together as on the development sets 1662–1671 "
           "(0.66–0.74)"};

// Plant drift=0.02 on fresh seed-1713 logs, where the screen lists no drift
// and the drift probe (drift_probe.h) proposes the loadcells' group.
struct DriftProbe {
  Between rate_vs_plant;   // the group's re-estimated rate / the plant's 0.02
  Below group_vs_before;   // summed loadcell RMSE after / before
  Below group_vs_control;  // summed loadcell RMSE after / fine-tuning alone's
  Below decision_p;        // the Diebold-Mariano p against fine-tuning alone
  const char* why;
};
inline constexpr DriftProbe kDriftProbe{
    .rate_vs_plant = {0.7, 1.6, 1.36},
    .group_vs_before = {0.8, 0.65},
    .group_vs_control = {0.92, 0.80},
    .decision_p = {0.01, 0.00018},
    .why = "the build's model reads the group's rate high on these logs (1.36×; the 4-seed model 1.25× on the "
           "same seed), so the rate's bound is wider than the screen's drift's; the bias state on all nine "
           "loadcells must cut well beyond fine-tuning alone, and the decision confirm it at alpha"};

// Plant default drift (0.004 N per N s plus a 0.01 N/sqrt(step) walk) on 1 000-step logs.
struct DefaultDriftLongLogs {
  Below winner_vs_before;   // the winner (fc2); no bound against the control
  Between rate_vs_plant;    // the winner's re-estimated rate / the plant's 0.004
  Below decision_p;         // the Diebold-Mariano p against fine-tuning alone
  const char* why;
};
inline constexpr DefaultDriftLongLogs kDefaultDriftLongLogs{
    .winner_vs_before = {0.75, 0.59},
    .rate_vs_plant = {0.5, 2.0, 0.893},
    .decision_p = {0.05, 3.5e-7},
    .why = "at this strength most of the cut is the fine-tuning's (0.68× alone); with one fold the decision "
           "was borderline (p 0.0065 with 2 threads, 0.0095 with 1; alpha 0.01), with two 4.5e-5 (2.4e-6 with the "
           "driver of the level, 3.5e-7 with the plan extended to fc1 and fc6 where the test finds it), and the "
           "test still asks for the candidate and its evaluation, not the verdict; the walk adds its own "
           "slow bias to the rate"};

// Plant: every loadcell clipped at 2 N (saturation=2).
struct Saturation {
  Below winner_vs_before;   // the winner (fc6)
  Below winner_vs_control;
  Below rail_error_N;       // |rail - 2 N| of every clip (measured: the largest, fc3)
  const char* why;
};
inline constexpr Saturation kSaturation{
    .winner_vs_before = {0.85, 0.74},
    .winner_vs_control = {0.97, 0.93},
    .rail_error_N = {0.1, 0.051},
    .why = "a rail is the measured maximum: sensor noise (20 mN) and quantisation on top of 2 N; training on "
           "the clipped output gains little on the winner beyond fine-tuning alone (the clip's gain is on "
           "fc3: 0.55× before)"};

// A slow synthetic aux_temp column adding 0.5 N per unit to fc3 on clean plant logs.
struct Aux {
  Below winner_vs_before;   // fc3
  Below winner_vs_control;
  const char* why;
};
inline constexpr Aux kAux{
    .winner_vs_before = {0.8, 0.72},
    .winner_vs_control = {0.95, 0.91},
    .why = "fine-tuning alone absorbs much of the slow aux term through the PB and the recurrent state (0.80× "
           "before), so the input is asked for a further 5 %"};

// Not the hand: two mass-springs, v1 reported 2 steps late (generic_layout_test.cc).
struct SpringDelay {
  Below winner_vs_before;   // v1
  Below winner_vs_control;
  const char* why;
};
inline constexpr SpringDelay kSpringDelay{
    .winner_vs_before = {0.6, 0.46},
    .winner_vs_control = {0.8, 0.64},
    .why = "an input delay on v1 ranks first and is declined (one group, beside a significant sensor delay), so "
           "--fix must take the sensor delay; "
           "the small model's alignment gain is smaller than the hand's"};

// ---- The docs table (docs/residual.md, "Test margins") ----

inline std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
inline std::string text(const Below& b) { return "< " + number(b.limit) + " (" + number(b.measured) + ")"; }
inline std::string text(const Above& b) { return "> " + number(b.limit) + " (" + number(b.measured) + ")"; }
inline std::string text(const Between& b) {
  return "within " + number(b.lo) + "–" + number(b.hi) + " (" + number(b.measured) + ")";
}
inline std::string worst(const Below& b) {
  return "< " + number(b.limit) + " (worst " + number(b.measured) + ")";
}

// The table's lines, header first: effect | winner after / before | vs
// control | other checks | why (bounds with the measured value in brackets).
inline std::vector<std::string> margins_table() {
  const std::string none = "—";
  struct Row {
    std::string effect, vs_before, vs_control, other, why;
  };
  const std::vector<Row> rows = {
      {"clean", none, none, "status `no significant effect`, weights bit-identical, nothing fine-tuned",
       "exact: with nothing significant nothing may change"},
      {"sensor-delay", text(kSensorDelay.winner_vs_before), text(kSensorDelay.winner_vs_control),
       std::to_string(kSensorDelay.delay_steps) + " steps on all " + std::to_string(kSensorDelay.aligned_channels) +
           " loadcells; every aligned channel " + worst(kSensorDelay.aligned_vs_before) + "; their median " +
           text(kSensorDelay.aligned_median),
       kSensorDelay.why},
      {"friction", text(kFriction.winner_vs_before), text(kFriction.winner_vs_control),
       "two derived inputs per family muscle; every family channel " + worst(kFriction.family_vs_before),
       kFriction.why},
      {"input-delay", text(kInputDelay.winner_vs_before), text(kInputDelay.winner_vs_control),
       "the 8 commands 2 steps earlier as inputs; every family channel " + worst(kInputDelay.family_vs_before),
       kInputDelay.why},
      {"sensor-curve", text(kSensorCurve.winner_vs_before), text(kSensorCurve.winner_vs_control),
       "curves on loadcells only; the winner's reading at its top knot within " +
           number(100 * kSensorCurve.winner_reading_error.limit) + " % of the plant's (" +
           number(100 * kSensorCurve.winner_reading_error.measured) + " %); every family channel " +
           worst(kSensorCurve.family_vs_before),
       kSensorCurve.why},
      {"crosstalk", text(kCrosstalk.winner_vs_before), text(kCrosstalk.winner_vs_control),
       "fitted gain " + text(kCrosstalk.gain) + "; target's held-out Ljung-Box p " +
           text(kCrosstalk.target_ljung_box_p) + "; the further pair's target " +
           text(kCrosstalk.further_vs_before) + " of before, " + text(kCrosstalk.further_vs_control) +
           " of fine-tuning alone",
       kCrosstalk.why},
      {"drift", text(kDrift.winner_vs_before), text(kDrift.winner_vs_control),
       "re-estimated rate / the plant's " + text(kDrift.rate_vs_plant) + "; every family channel " +
           worst(kDrift.family_vs_before) + "; all nine loadcells at one rate, each / fine-tuning alone " +
           worst(kDrift.each_vs_control) + ", their summed RMSE " + text(kDrift.group_vs_control) + " of its",
       kDrift.why},
      {"drift probe (seed 1713)", "summed loadcells " + text(kDriftProbe.group_vs_before),
       "summed loadcells " + text(kDriftProbe.group_vs_control),
       "the probe's candidate chosen (or, since stop 74, applied as the chosen curve's rival) and confirmed (decision p " + text(kDriftProbe.decision_p) +
           "); all nine loadcells at one rate, re-estimated rate / the plant's " + text(kDriftProbe.rate_vs_plant),
       kDriftProbe.why},
      {"default drift, 1 000 steps", text(kDefaultDriftLongLogs.winner_vs_before), none,
       "re-estimated rate / the plant's " + text(kDefaultDriftLongLogs.rate_vs_plant) +
           "; decision p against fine-tuning alone " + text(kDefaultDriftLongLogs.decision_p),
       kDefaultDriftLongLogs.why},
      {"saturation", text(kSaturation.winner_vs_before), text(kSaturation.winner_vs_control),
       "every rail within " + number(kSaturation.rail_error_N.limit) + " N of 2 N (" +
           number(kSaturation.rail_error_N.measured) + "); no prediction of a clipped channel above its rail",
       kSaturation.why},
      {"aux", text(kAux.winner_vs_before), text(kAux.winner_vs_control), "dims.x and dims.y + 1", kAux.why},
      {"spring delay (not the hand)", text(kSpringDelay.winner_vs_before), text(kSpringDelay.winner_vs_control),
       "v1 aligned by 2 steps; clean spring logs give `no significant effect`", kSpringDelay.why},
  };
  std::vector<std::string> lines = {
      "| effect | winner after / before (measured) | vs control (measured) | other checks | why |",
      "|---|---|---|---|---|"};
  for (const Row& r : rows)
    lines.push_back("| " + r.effect + " | " + r.vs_before + " | " + r.vs_control + " | " + r.other + " | " + r.why +
                    " |");
  return lines;
}

}  // namespace hadynet::test::fix_margins
