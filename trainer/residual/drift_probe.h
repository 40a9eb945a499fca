// The drift probe of --fix (docs/residual-experiments.md, "A drift probe of the
// unchanged network"): a second screen, for the one effect the regression
// screen rarely lists.
//
// A sensor bias that grows slowly through a log leaves little in the 1-step
// residual: the network carries most of it over from the measured history,
// and the screen's test whitens what is left into its row-to-row increment
// (attribution.h). What the bias does show is in the network's own
// predictions: fed readings that carry the bias, it mispredicts the
// dynamics, and fed the readings with the bias removed (the fix's own frame:
// BiasState, sensor_model.h) it predicts them better. The probe asks that
// question directly, per channel group, with the unchanged network:
//
//   1. The plan: a load drift on every channel of the group at one rate
//      (BiasState::common_rate; sensors of one kind age together), the
//      grid's start at start_rate() (a bias at a log's end of a quarter of
//      the channels' standardisation std at their mean load).
//   2. The rate re-estimated as the fix re-estimates it (BiasState::refine:
//      the unchanged network's summed 1-step MSE of the group, on a grid of 0
//      and 1/4..16 times the start) on the selection's training rows
//      (DecisionRows::selection_train).
//   3. Judged on the selection's judged rows (DecisionRows::selection_judged,
//      training rows the rate did not see): a one-sided Diebold-Mariano test
//      of the unchanged network's per-row standardised loss over the group,
//      without the drift minus with it.
//   4. Holm's correction over the groups tested (those whose re-estimated
//      rate is positive: the rate is fitted on rows the test does not
//      judge); a group is a candidate when its adjusted p is below alpha
//      with a positive gain.
//
// The probe proposes only: every candidate group joins fix()'s
// candidates (the smallest adjusted p first; until stop 71 only the best),
// right after the screen's load drifts of that group or after the screen's
// candidates; it is judged on the training rows like them (a load drift of
// its group chosen there gives way to it when it gains too and predicts
// their channels better: gives_way_to_group_drift; a calibration curve or a
// drift with time chosen there has the load drifts of its group among its
// rivals on the held-out rows, and either drift chosen there every probe's
// plan: decision_rivals), and only
// the decision on the held-out rows, against fine-tuning alone, confirms it
// (augment.h, fix()). The held-out rows play no part here. Nothing here
// knows the hand: groups come from the model's channel names
// (channel_group).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "trainer/residual/augment.h"

namespace hadynet::trainer::residual {

// DriftProbe (one group's probe) is declared in augment.h, beside
// CandidateTrial: FixResult holds the probes fix() ran.


// The load drift on every one of `channels` (one group) at one common rate,
// each channel's bias growing with its own level (BiasState), starting at
// `rate`: the probe's plan, and the candidate fix() tries.
Augmentation group_drift_plan(const std::vector<std::string>& channels, double period_s, double rate);

// The grid's start for `channels` of `data` (the analysed logs, the model's
// frame): the rate at which the bias at a log's end, rate * sum_t |y_c| dt,
// is a quarter of the channel's standardisation std (ResidualData::y_scale),
// both averaged over the channels and logs; 0 when the channels carry no
// level. On the grid of 1/4..16 times it, the bias at a log's end ranges
// from 1/16 to 4 times the std.
double start_rate(const ResidualData& data, const std::vector<std::string>& channels);

// What the probe needs of fix(): the plan re-estimated on the selection's
// training rows (fix()'s refinement), and the unchanged network's per-row
// loss on the selection's judged rows with a sensor model (the mean over
// `channels` of the standardised error, squared or absolute as fix()'s tests:
// FixOptions::decision_loss; one segment per log).
struct DriftProbeRows {
  std::function<Augmentation(const Augmentation& plan)> refined;
  std::function<Segments(const SensorModel& sensor, const std::vector<std::string>& channels)> loss;
};

// Probes every channel group of the model's y channels that its sensor
// model does not already give a drift, in the order the groups first
// appear. `data`: the analysis of the logs (dt_s and levels).
std::vector<DriftProbe> probe_drifts(const HadynetModel& model, const ResidualData& data, const DriftProbeRows& rows,
                                     double alpha);

// The candidate probes, the smallest adjusted p first (equals in `probes`'
// order); empty when none is a candidate. On drift set 2981 (stop 70) the
// joint angles' probe had the smaller p (1.4e-05, rate 0.0037) and the
// loadcells' (5.4e-05, at the plant's rate 0.021) was not proposed.
std::vector<const DriftProbe*> candidate_drift_probes(const std::vector<DriftProbe>& probes);

}  // namespace hadynet::trainer::residual
