// The analysis half of the residual loop as one call (docs/residual.md): a
// model's residuals over logs, its multi-step fit, the residual tests
// (whiteness, independence) and the effect library's attribution, with one
// verdict text. `hadynet residual` is a shell around analyse() and the
// report writers (cli/residual_report.h); tests and benchmarks call it the
// same way.
#pragma once

#include <string>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/residual/attribution.h"
#include "trainer/residual/effects.h"
#include "trainer/residual/residuals.h"
#include "trainer/residual/whiteness.h"

namespace hadynet::trainer::residual {

struct AnalysisOptions {
  std::string pb_choice = "auto";  // compute_residuals(): auto, state, adapt, zero, a state, values
  int horizon = 0;                 // multi-step horizon in steps; 0: the model's N_train
  int max_lag = kDefaultMaxLag;    // whiteness lags 1..L, independence -L..L
  LibraryOptions library;          // which hypotheses are enumerated
  AttributionOptions attribution;  // how they are fitted and tested
  // Where the reference logs came from, or why there are none, in words for
  // floors_summary() (e.g. "the model's held-out logs"); may be empty.
  std::string null_source;
  // The PB rule for the reference logs (compute_residuals); empty: pb_choice.
  // The model's stored held-out logs are rows of its trained states' own
  // recordings, so their trained PBs are theirs ("state"): no PB check.
  std::string reference_pb_choice;
  // The sensor model the reference logs were recorded through, when it is
  // not the model's: a --rounds round analyses a model whose sensor model
  // holds the changes earlier rounds confirmed on the logs under test, which
  // the clean reference logs do not show (`hadynet residual`: the stored
  // held-out logs' sensors are the training logs', no sensor model but the
  // clips; --reference logs', the input model's). nullptr: the model's own.
  const SensorModel* reference_sensor = nullptr;
};

// Everything the analysis computes.
struct Analysis {
  ResidualData data;
  HorizonMetrics horizon;
  int max_lag = kDefaultMaxLag;
  std::vector<Whiteness> whiteness;                         // per y channel
  std::vector<std::vector<CrossCorrelation>> with_inputs;    // [c][j]: residual of y_c with u_j
  std::vector<std::vector<CrossCorrelation>> with_observed;  // [c][j]: with y_j (j != c; [c][c] empty)
  Attribution attribution;  // with attribution.null when reference logs were given
  std::string reference_pb;  // with reference logs: pb_summary() of the reference
  std::string null_source;   // AnalysisOptions::null_source
  std::string verdict;  // verdict_text(attribution)
};

// Runs the whole analysis. With `reference` logs (clean, the same channels;
// never the model's training data nor `logs`), the floors are calibrated on
// them (calibrate_null(), attribution.h); without, the absolute floors of
// options.attribution hold. Throws std::runtime_error naming the log or the
// bad PB text (compute_residuals), or when the model's prediction is not
// finite on these logs (never a table of NaN with a verdict under it);
// std::invalid_argument when the reference's channels differ.
Analysis analyse(const HadynetModel& model, const std::vector<LogInput>& logs, const AnalysisOptions& options,
                 const std::vector<LogInput>& reference = {});

// `model` with the sensor model of the reference logs (nullptr: its own):
// the model that computes the null's residuals (AnalysisOptions::reference_sensor).
HadynetModel with_reference_sensor(const HadynetModel& model, const SensorModel* reference_sensor);

// The reference logs as a plant with `model`'s input dead time would have
// recorded them: the null's clean logs in the model's world, as
// with_reference_sensor() reads them through the sensors they were
// recorded with. A model whose u holds lag<d>_<c> inputs (an input dead
// time, docs/residual.md "Input dead time") acts on commands d steps late,
// so each command column c it lags is advanced by its largest d (row t
// holds u_c(t + d)) and every log loses its last D rows (D: the largest d).
// A log recorded without dead time then shows exactly d steps of it:
// lag<d>_<c>(t) is the command that moved the plant at t. Without lag
// inputs the logs are returned unchanged. Throws std::invalid_argument
// naming the log when it lacks a lagged command column or has no more than
// D rows.
std::vector<LogInput> with_model_dead_time(const HadynetModel& model, const std::vector<LogInput>& reference);

// What the floors of an analysis were, in words: the calibrated null (logs,
// PBs) or the absolute floors assumed without one.
std::string floors_summary(const Analysis& analysis);

// The one wording of a verdict: "no significant effect", or
// "<effect>: <winner's label>; also significant: <label>, ..." listing the
// rest of the winner's family (the same effect on other channels).
std::string verdict_text(const Attribution& attribution);

// Which PB each log used, in words: e.g. "--pb auto: 3 logs with their
// state's trained PB, 1 log with a PB adapted to its state's logs (a state
// the model was not trained on)". An adapted PB is never left unsaid.
std::string pb_summary(const ResidualData& data, const std::string& pb_choice);

// What a ranked hypothesis' numbers say, for listings next to its p-value:
// "significant", "not testable", "over-predicts held out" (its fitted effect
// raises the held-out residual: explained < 0, whatever p says),
// "below the floors" (significant p, too little explained) or "not significant".
const char* hypothesis_status(const HypothesisResult& result, const AttributionOptions& options);

// The hypothesis a report shows in detail: the winner when there is one,
// else the testable hypothesis with the largest floor_statistic() (explained
// in standardised units, or beyond the null; labelled "not significant"); nullptr when nothing was testable.
const HypothesisResult* hypothesis_to_show(const Attribution& attribution);

// The fitted prediction Z beta of a hypothesis, per log (0 where the
// regressors are undefined).
Segments fitted_segments(const ResidualData& data, const HypothesisResult& result);

}  // namespace hadynet::trainer::residual
