#include "trainer/residual/analysis.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "trainer/derived_inputs.h"
#include "trainer/sensor_model.h"

namespace hadynet::trainer::residual {

Analysis analyse(const HadynetModel& model, const std::vector<LogInput>& logs, const AnalysisOptions& options,
                 const std::vector<LogInput>& reference) {
  Analysis a;
  a.max_lag = options.max_lag;
  a.null_source = options.null_source;
  a.data = compute_residuals(model, logs, options.pb_choice);
  a.horizon = horizon_metrics(model, a.data, options.horizon > 0 ? options.horizon : model.train_steps);
  if (!a.horizon.rmse.allFinite()) {
    throw std::runtime_error("the model's prediction is not finite on these logs (float32 overflow in the "
                             "network); no residual can be analysed");
  }
  const auto& d = a.data;
  const std::size_t ny = d.y_names.size(), nu = d.u_names.size();
  a.with_inputs.assign(ny, {});
  a.with_observed.assign(ny, std::vector<CrossCorrelation>(ny));
  std::vector<Segments> inputs, observed;
  for (std::size_t j = 0; j < nu; ++j) inputs.push_back(input_segments(d, static_cast<int>(j)));
  for (std::size_t j = 0; j < ny; ++j) observed.push_back(observed_segments(d, static_cast<int>(j)));
  for (std::size_t c = 0; c < ny; ++c) {
    const Segments r = residual_segments(d, static_cast<int>(c));
    a.whiteness.push_back(whiteness(r, a.max_lag));
    for (std::size_t j = 0; j < nu; ++j) a.with_inputs[c].push_back(cross_correlate(r, inputs[j], a.max_lag));
    for (std::size_t j = 0; j < ny; ++j)
      if (j != c) a.with_observed[c][j] = cross_correlate(r, observed[j], a.max_lag);
  }
  LibraryOptions library = options.library;
  library.sensor_curves = !reference.empty();
  const std::vector<Hypothesis> hypotheses = enumerate_hypotheses(d, library);
  if (reference.empty()) {
    a.attribution = attribute(d, hypotheses, options.attribution);
  } else {
    const std::string& ref_pb = options.reference_pb_choice.empty() ? options.pb_choice : options.reference_pb_choice;
    const ResidualData ref = compute_residuals(with_reference_sensor(model, options.reference_sensor),
                                               with_model_dead_time(model, reference), ref_pb);
    a.reference_pb = pb_summary(ref, ref_pb);
    const NullCalibration null = calibrate_null(d, ref, hypotheses, options.attribution);
    a.attribution = attribute(d, hypotheses, options.attribution, &null);
  }
  a.verdict = verdict_text(a.attribution);
  return a;
}

HadynetModel with_reference_sensor(const HadynetModel& model, const SensorModel* reference_sensor) {
  HadynetModel m = model;
  if (reference_sensor != nullptr) m.sensor = *reference_sensor;
  return m;
}

std::vector<LogInput> with_model_dead_time(const HadynetModel& model, const std::vector<LogInput>& reference) {
  // Each lagged command column, advanced by its largest lag: the shift
  // time_aligned() gives a delayed sensor's column.
  std::map<std::string, int> lead;
  int rows_lost = 0;
  for (const auto& name : model.layout.u_names) {
    const std::optional<DerivedInput> d = parse_derived_input(name);
    if (!d || d->kind != DerivedKind::kLag) continue;
    int& steps = lead[d->base];
    steps = std::max(steps, d->lag);
    rows_lost = std::max(rows_lost, d->lag);
  }
  if (lead.empty()) return reference;
  std::vector<SensorDelay> advances;
  for (const auto& [base, steps] : lead) advances.push_back({base, steps});
  std::vector<LogInput> out;
  out.reserve(reference.size());
  for (const LogInput& log : reference) {
    const std::size_t rows = log.table.rows();
    if (rows <= static_cast<std::size_t>(rows_lost))
      throw std::invalid_argument(log.file + ": a reference log of " + std::to_string(rows) +
                                  " rows cannot show the model's input dead time of " + std::to_string(rows_lost) +
                                  " steps");
    for (const auto& [base, steps] : lead)
      if (!log.table.column_index(base))
        throw std::invalid_argument(log.file + ": the reference log has no command column " + base);
    out.push_back({time_aligned(log.table, log.file, advances), log.file});
  }
  return out;
}

std::string floors_summary(const Analysis& a) {
  const auto& o = a.attribution.options;
  const std::string source = a.null_source.empty() ? std::string() : " (" + a.null_source + ")";
  char buf[512];
  if (!a.attribution.null) {
    std::snprintf(buf, sizeof buf,
                  "floors: no calibrated null%s: absolute floors assumed, an effect must lower its "
                  "channel's standardised 1-step loss by >= %g (set for the hand's models) and explain >= %g of "
                  "its held-out residual variance; calibration curves are not tested (they need a null)",
                  source.c_str(), o.min_explained_std, o.min_explained);
    return buf;
  }
  std::snprintf(buf, sizeof buf,
                "floors: calibrated null of %ld reference logs%s, %s: an effect must explain >= %g times its "
                "channel's clean residual level more than on the null, and >= %g of its held-out residual variance",
                a.attribution.null->logs, source.c_str(), a.reference_pb.c_str(), o.min_excess_null, o.min_explained);
  return buf;
}

std::string verdict_text(const Attribution& attribution) {
  const auto w = attribution.winner();
  if (!w) return "no significant effect";
  std::string v = w->effect + ": " + w->label;
  const auto family = attribution.winner_family();
  if (family.size() > 1) {
    v += "; also significant:";
    for (std::size_t i = 1; i < family.size(); ++i) {
      v += (i > 1 ? ", " : " ");
      v += family[i].label;
    }
  }
  return v;
}

std::string pb_summary(const ResidualData& data, const std::string& pb_choice) {
  std::map<std::string, int> logs_by_source;  // given PBs, by their text
  int trained = 0, adapted = 0, replaced = 0;
  for (const auto& log : data.logs) {
    if (log.pb_origin == ResidualLog::PbOrigin::kTrained) {
      ++trained;
    } else if (log.pb_origin == ResidualLog::PbOrigin::kAdapted) {
      ++adapted;
    } else if (log.pb_origin == ResidualLog::PbOrigin::kAdaptedOverTrained) {
      ++replaced;
    } else {
      ++logs_by_source[log.pb_source];
    }
  }
  const auto logs = [](int n) { return std::to_string(n) + (n == 1 ? " log" : " logs"); };
  std::string s = "--pb " + pb_choice + ":";
  std::string sep = " ";
  if (trained > 0) {
    s += sep + logs(trained) + " with their state's trained PB";
    sep = ", ";
  }
  if (adapted > 0) {
    s += sep + logs(adapted) + " with a PB adapted to their state's logs" +
         (pb_choice == "auto" ? " (states the model was not trained on)" : "");
    sep = ", ";
  }
  if (replaced > 0) {
    s += sep + logs(replaced) + " with a PB adapted to their state's logs (the state's trained PB predicted "
                                "their held-out rows worse: re-zeroed, worn, or grasped unlike the training logs)";
    sep = ", ";
  }
  for (const auto& [source, n] : logs_by_source) {
    s += sep + logs(n) + " with PB " + source;
    sep = ", ";
  }
  return s;
}

const char* hypothesis_status(const HypothesisResult& r, const AttributionOptions& options) {
  if (r.significant) return "significant";
  if (!r.testable) return "not testable";
  if (r.explained < 0) return "over-predicts held out";
  if (r.p_adjusted < options.alpha) return "below the floors";
  return "not significant";
}

const HypothesisResult* hypothesis_to_show(const Attribution& attribution) {
  if (!attribution.ranked.empty() && attribution.ranked.front().significant) return &attribution.ranked.front();
  const HypothesisResult* best = nullptr;
  for (const auto& r : attribution.ranked)
    if (r.testable && (best == nullptr || floor_statistic(attribution, r) > floor_statistic(attribution, *best)))
      best = &r;
  return best;
}

Segments fitted_segments(const ResidualData& data, const HypothesisResult& result) {
  Segments out;
  for (const auto& log : data.logs) {
    const Features f = features(result.hypothesis, log);
    Eigen::VectorXd p = f.z * result.coef;
    p.head(f.first_valid).setZero();
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace hadynet::trainer::residual
