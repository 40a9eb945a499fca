#include "trainer/residual/augment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "trainer/derived_inputs.h"
#include "trainer/residual/analysis.h"

namespace hadynet::trainer::residual {

namespace {

int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s;
}

// Per held-out row (one segment per log): the mean over `channels` of the
// squared error in the model's standardised units (the training loss's).
Segments standardised_loss(const HadynetModel& model, const HeldOutError& e, const std::vector<std::string>& channels) {
  Segments out;
  for (const auto& name : channels) {
    const int c = index_of(e.channels, name);
    const int k = index_of(model.layout.y_names, name);
    if (c < 0 || k < 0) throw std::logic_error("--fix: channel " + name + " missing from a held-out evaluation");
    const double scale = model.norm.y.std(k);
    const Segments& r = e.residuals[static_cast<std::size_t>(c)];
    if (out.empty()) out.assign(r.size(), Eigen::VectorXd());
    for (std::size_t s = 0; s < r.size(); ++s) {
      const Eigen::VectorXd sq = (r[s] / scale).array().square().matrix() / static_cast<double>(channels.size());
      out[s] = out[s].size() == 0 ? sq : (out[s] + sq).eval();
    }
  }
  return out;
}

}  // namespace

bool fix_supported(EffectKind kind) { return kind != EffectKind::kInputDelay; }

std::optional<Augmentation> plan_augmentation(const ResidualData& data, const Attribution& attribution) {
  const auto winner = attribution.winner();
  if (!winner) return std::nullopt;
  // The best significant hypothesis whose effect --fix can add: the winner,
  // unless its effect has no augmentation (input-delay), then the next one
  // in the ranking. A sensor delay on a channel the commands drive directly
  // leaves nearly the residual of an input delay on that channel alone, so
  // the two can swap places (docs/residual.md).
  const HypothesisResult* w = nullptr;
  for (const auto& r : attribution.ranked) {
    if (!r.significant) break;
    if (fix_supported(r.hypothesis.kind)) {
      w = &r;
      break;
    }
  }
  Augmentation a;
  if (w == nullptr) {  // nothing significant can be added: fix() says "not supported"
    a.kind = winner->hypothesis.kind;
    a.effect = winner->effect;
    a.description = effect_info(a.kind).augmentation;
    return a;
  }
  a.kind = w->hypothesis.kind;
  a.effect = w->effect;
  const auto& h = w->hypothesis;
  switch (h.kind) {
    case EffectKind::kSensorDelay: {
      a.delay = h.delay;
      for (const auto& r : attribution.family_of(*w))
        if (r.hypothesis.delay == h.delay) a.channels.push_back(data.y_names[static_cast<std::size_t>(r.hypothesis.target)]);
      // A delay belongs to the acquisition chain, so it extends to the other
      // channels of the winner's group where the same delay passes the test
      // (Holm-adjusted p < alpha, positive gain) without the practical
      // floors: the floors guard against naming the model's own misfit as a
      // new effect; here the effect is established and the test only says
      // where else it is. A loadcell that barely moves leaves a small
      // residual, but aligning it is still right (docs/residual.md).
      const std::string group = channel_group(data.y_names[static_cast<std::size_t>(h.target)]);
      std::vector<std::string> extended;
      for (const auto& r : attribution.ranked) {
        const auto& hr = r.hypothesis;
        const std::string& name = data.y_names[static_cast<std::size_t>(hr.target)];
        if (hr.kind != EffectKind::kSensorDelay || hr.delay != h.delay || channel_group(name) != group) continue;
        if (!r.testable || r.p_adjusted >= attribution.options.alpha || !(r.parameter > 0)) continue;
        if (std::find(a.channels.begin(), a.channels.end(), name) != a.channels.end()) continue;
        a.channels.push_back(name);
        extended.push_back(name);
      }
      a.description = "time-align " + join(a.channels) + " by " + std::to_string(a.delay) + " steps" +
                      (extended.empty() ? "" : " (" + join(extended) + ": the same delay in the same group)") +
                      "; the model predicts the true-time signal";
      break;
    }
    case EffectKind::kAuxChannel:
      a.channels = {data.aux_names[static_cast<std::size_t>(h.source)]};
      a.description = "use " + a.channels[0] + " as an observed channel (input of x, predicted in y)";
      break;
    case EffectKind::kCrosstalk: {
      // The winner's pair only. Removing every pair of the family was
      // measured worse: between correlated sources the family holds pairs
      // the plant does not have (fc6 -> fc5 with gain -0.27 on the default
      // plant logs), and fc1 got worse than before (docs/residual.md).
      a.channels = {data.y_names[static_cast<std::size_t>(h.target)]};
      a.source = data.y_names[static_cast<std::size_t>(h.source)];
      a.gain = w->parameter;
      a.crosstalk = {{a.channels[0], a.source, a.gain}};
      char gain[32];
      std::snprintf(gain, sizeof gain, "%.4g", a.gain);
      a.description = "remove the crosstalk " + a.source + " -> " + a.channels[0] + " (train on " + a.channels[0] +
                      " - " + gain + " " + a.source + "; the sensor model adds it back)";
      break;
    }
    case EffectKind::kFriction: {
      std::vector<std::string> muscles;
      for (const auto& r : attribution.family_of(*w)) {
        a.channels.push_back(data.y_names[static_cast<std::size_t>(r.hypothesis.target)]);
        const std::string& m = data.u_names[static_cast<std::size_t>(r.hypothesis.source)];
        if (std::find(muscles.begin(), muscles.end(), m) == muscles.end()) muscles.push_back(m);
      }
      for (const auto& m : muscles)
        for (const DerivedKind k : {DerivedKind::kSign, DerivedKind::kHysteresis})
          a.inputs.push_back(derived_input_name({k, m}));
      a.description = "add the hysteresis state of " + join(muscles) + " as inputs (" + join(a.inputs) +
                      "; friction on " + join(a.channels) + ")";
      break;
    }
    case EffectKind::kSaturation: {
      std::vector<std::string> rails;
      for (const auto& r : attribution.family_of(*w)) {
        const auto& hr = r.hypothesis;
        a.channels.push_back(data.y_names[static_cast<std::size_t>(hr.target)]);
        a.clips.push_back({a.channels.back(), hr.side, hr.rail});
        char text[96];
        std::snprintf(text, sizeof text, "%s %s %.4g", a.channels.back().c_str(), hr.side > 0 ? "<=" : ">=", hr.rail);
        rails.push_back(text);
      }
      a.description = "clip the prediction at the measured rail: " + join(rails) + " (trained on the clipped output)";
      break;
    }
    case EffectKind::kDriftLoad:
    case EffectKind::kDriftTime: {
      a.period_s = data.logs.front().dt_s;
      for (const auto& log : data.logs)
        if (log.dt_s != a.period_s)
          throw std::runtime_error(log.seq.file + ": dt_s differs from the other logs' (a drift needs one period)");
      for (const auto& r : attribution.family_of(*w)) {
        a.channels.push_back(data.y_names[static_cast<std::size_t>(r.hypothesis.target)]);
        a.drifts.push_back({a.channels.back(), h.kind == EffectKind::kDriftLoad, r.parameter});
      }
      a.description = std::string("a bias state growing with ") +
                      (h.kind == EffectKind::kDriftLoad ? "the accumulated load" : "time") + " on " +
                      join(a.channels) + ", removed from the data and added to the prediction";
      break;
    }
    default:
      a.description = effect_info(h.kind).augmentation;
      break;
  }
  if (w->label != winner->label)
    a.description = "the winner (" + winner->effect + ": " + winner->label +
                    ") has no augmentation; the best significant effect that has: " + w->label + "; " + a.description;
  return a;
}

SensorModel sensor_after(const SensorModel& before, const Augmentation& a) {
  SensorModel s = before;
  switch (a.kind) {
    case EffectKind::kSensorDelay:
      // Found in the model's frame: a channel already aligned is late by its
      // old delay plus this one.
      for (const auto& c : a.channels) {
        const auto it = std::find_if(s.delays.begin(), s.delays.end(), [&](const SensorDelay& x) { return x.channel == c; });
        if (it != s.delays.end()) it->steps += a.delay;
        else s.delays.push_back({c, a.delay});
      }
      break;
    case EffectKind::kCrosstalk:
      s.crosstalk.insert(s.crosstalk.end(), a.crosstalk.begin(), a.crosstalk.end());
      break;
    case EffectKind::kDriftLoad:
    case EffectKind::kDriftTime:
      s.drifts.insert(s.drifts.end(), a.drifts.begin(), a.drifts.end());
      s.period_s = a.period_s;
      break;
    case EffectKind::kSaturation:
      for (const OutputClip& c : a.clips) {
        const auto it = std::find_if(s.clips.begin(), s.clips.end(),
                                     [&](const OutputClip& o) { return o.channel == c.channel && o.side == c.side; });
        if (it != s.clips.end()) *it = c;
        else s.clips.push_back(c);
      }
      break;
    default:
      break;
  }
  return s;
}

std::vector<LogInput> model_frame_logs(const SensorModel& sensor, const std::vector<LogInput>& logs) {
  if (sensor.frame_is_measured()) return logs;
  std::vector<LogInput> out;
  for (const auto& in : logs) out.push_back({to_model_frame(sensor, in.table, in.file), in.file});
  return out;
}

FeatureLayout augmented_layout(const FeatureLayout& layout, const Augmentation& a) {
  std::vector<std::string> y = layout.y_names, u = layout.u_names;
  if (a.kind == EffectKind::kAuxChannel) y.push_back(a.channels.at(0));
  u.insert(u.end(), a.inputs.begin(), a.inputs.end());
  return feature_layout_from_names(y, u, layout.delta_groups);
}

namespace {

// Mean and population std of row `row` over the training sequences' `Eigen::MatrixXd LogSequence::*` rows.
std::pair<double, double> row_moments(const std::vector<LogSequence>& seqs, Eigen::MatrixXd LogSequence::*part,
                                      Eigen::Index row, const std::string& name) {
  double sum = 0, sum_sq = 0;
  long n = 0;
  for (const auto& s : seqs) {
    if ((s.*part).rows() <= row) throw std::invalid_argument("--fix: training logs lack " + name);
    sum += (s.*part).row(row).sum();
    sum_sq += (s.*part).row(row).squaredNorm();
    n += s.steps();
  }
  if (n == 0) throw std::invalid_argument("--fix: no training rows");
  const double mean = sum / static_cast<double>(n);
  const double sd = std::sqrt(std::max(0.0, sum_sq / static_cast<double>(n) - mean * mean));
  return {mean, sd > 0 ? sd : 1.0};
}

void append(Eigen::VectorXd& v, double value) {
  v.conservativeResize(v.size() + 1);
  v(v.size() - 1) = value;
}

// `m` (a copy of `model`) with the derived command channels `inputs` appended
// to u: standardisation from the training rows (whose u holds them, last),
// zero LSTM input weights (inputs are [u ; p]).
HadynetModel with_derived_inputs(const HadynetModel& model, HadynetModel m, const Augmentation& a,
                                 const std::vector<LogSequence>& train_seqs) {
  const std::vector<std::string>& inputs = a.inputs;
  m.layout = augmented_layout(model.layout, a);
  const auto u_old = static_cast<Eigen::Index>(model.layout.u_names.size());
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const auto [mean, sd] = row_moments(train_seqs, &LogSequence::u, u_old + static_cast<Eigen::Index>(i), inputs[i]);
    append(m.norm.u.mean, mean);
    append(m.norm.u.std, sd);
  }
  auto& p = m.params;
  const auto k = static_cast<Eigen::Index>(inputs.size());
  const Eigen::Index pb = p.dims.pb;
  RowMatrix<float> ih(p.lstm_weight_ih.rows(), u_old + k + pb);
  ih.setZero();
  ih.leftCols(u_old) = p.lstm_weight_ih.leftCols(u_old);
  ih.rightCols(pb) = p.lstm_weight_ih.rightCols(pb);
  p.lstm_weight_ih = ih;
  p.dims.u += static_cast<int>(k);
  p.check_shapes();
  return m;
}

}  // namespace

HadynetModel augmented_model(const HadynetModel& model, const Augmentation& a,
                             const std::vector<LogSequence>& train_seqs) {
  HadynetModel m = model;
  m.detection.reset();
  m.ranges.reset();
  const auto fixed = m.provenance.find("residual_fix");
  m.provenance["residual_fix"] = (fixed == m.provenance.end() ? "" : fixed->second + "; then ") + a.effect + ": " +
                                 a.description;
  m.sensor = sensor_after(model.sensor, a);
  if (a.kind == EffectKind::kSensorDelay || a.kind == EffectKind::kCrosstalk || a.kind == EffectKind::kSaturation ||
      a.kind == EffectKind::kDriftLoad || a.kind == EffectKind::kDriftTime)
    return m;
  if (a.kind == EffectKind::kFriction) return with_derived_inputs(model, m, a, train_seqs);
  if (a.kind != EffectKind::kAuxChannel) throw std::invalid_argument("--fix: " + a.effect + " is not implemented");
  const std::string& aux = a.channels.at(0);
  m.layout = augmented_layout(model.layout, a);
  const std::vector<std::string>& y = m.layout.y_names;
  // The aux group is last in y and not a delta group, so it is the last x channel.
  if (m.layout.x_names.back() != aux || m.layout.x_names.size() != model.layout.x_names.size() + 1)
    throw std::logic_error("--fix: unexpected x layout for " + aux);
  // Standardisation of the new channel over the training rows (population std).
  const auto row = static_cast<Eigen::Index>(y.size() - 1);
  const auto [mean, sd] = row_moments(train_seqs, &LogSequence::y, row, aux);
  append(m.norm.y.mean, mean);
  append(m.norm.y.std, sd);
  append(m.norm.x.mean, mean);
  append(m.norm.x.std, sd);

  // Network: a zero encoder column for the new x input (inputs are [x ; p]) and
  // a zero decoder row (the new output starts at the channel's mean).
  auto& p = m.params;
  const int x_old = p.dims.x, pb = p.dims.pb;
  RowMatrix<float> enc(p.enc_weight.rows(), x_old + 1 + pb);
  enc.setZero();
  enc.leftCols(x_old) = p.enc_weight.leftCols(x_old);
  enc.rightCols(pb) = p.enc_weight.rightCols(pb);
  p.enc_weight = enc;
  p.dec_weight.conservativeResize(p.dec_weight.rows() + 1, Eigen::NoChange);
  p.dec_weight.bottomRows(1).setZero();
  p.dec_bias.conservativeResize(p.dec_bias.size() + 1);
  p.dec_bias(p.dec_bias.size() - 1) = 0.0f;
  p.dims.x += 1;
  p.dims.y += 1;
  p.check_shapes();
  return m;
}

FixResult fix(const HadynetModel& model, const std::vector<LogInput>& logs, const ResidualData& data,
              const Attribution& attribution, const FixOptions& options) {
  if (logs.size() != data.logs.size()) throw std::invalid_argument("--fix: logs and analysis differ");
  FixResult result;
  result.model = model;
  result.augmentation = plan_augmentation(data, attribution);
  const Augmentation* aug = result.augmentation ? &*result.augmentation : nullptr;
  // Rows a sensor delay costs at the end of each log, before or after.
  const int d = std::max(model.sensor.max_delay(), aug != nullptr ? sensor_after(model.sensor, *aug).max_delay() : 0);

  // Held-out rows of each log: [first, end), the same for every model.
  std::vector<int> split;
  for (const auto& in : logs) {
    const int T = static_cast<int>(in.table.rows());
    const int first = std::max(static_cast<int>(std::floor(options.train_fraction * T)), d + 2);
    if (first >= T - d) throw std::runtime_error(in.file + ": too short for --fix's time split");
    split.push_back(first);
  }
  // Each model is fed the logs in its own frame and judged on the measured rows.
  auto eval_logs = [&](const HadynetModel& m, const std::vector<Eigen::VectorXf>& pbs) {
    const std::vector<LogInput> frame_logs = model_frame_logs(m.sensor, logs);
    std::vector<HeldOutLog> out;
    for (std::size_t i = 0; i < logs.size(); ++i) {
      HeldOutLog e;
      e.raw = &logs[i];
      e.measured = log_sequence(logs[i].table, logs[i].file, m.layout);
      e.frame = log_sequence(frame_logs[i].table, frame_logs[i].file, m.layout);
      e.pb = pbs[i];
      e.first = split[i];
      e.end = e.measured.steps() - d;
      out.push_back(std::move(e));
    }
    return out;
  };
  auto state_pbs = [&](const HadynetModel& m) {
    std::vector<Eigen::VectorXf> pbs;
    for (const auto& log : data.logs) pbs.push_back(m.params.pb.row(m.state_index(log.seq.state)).transpose());
    return pbs;
  };
  const FineTuneOptions tuning{options.epochs, options.batch, options.lr, options.seed};
  std::vector<Eigen::VectorXf> before_pbs;
  for (const auto& log : data.logs) before_pbs.push_back(log.pb);
  result.before = held_out_error(model, eval_logs(model, before_pbs));
  result.before.verdict = verdict_text(attribution);

  if (aug == nullptr) {
    result.status = "no significant effect";
    return result;
  }
  if (!fix_supported(aug->kind)) {
    result.status = "not supported: " + aug->effect + ": " + aug->description;
    return result;
  }

  // Drift rates: the attribution's fit is low (the model carries part of a
  // bias over from x_t). Each channel's rate is re-estimated as the one, on a
  // grid of 0..5x the fitted rate in steps of 0.1x, that minimises the
  // unchanged network's 1-step RMSE of that channel in the measured frame on
  // the training rows (the bias removed from the inputs, added to the
  // prediction). Channels in family order, each with the others' rates so far.
  if (!aug->drifts.empty()) {
    Augmentation& a = *result.augmentation;
    HadynetModel probe = model;
    for (std::size_t k = 0; k < a.drifts.size(); ++k) {
      result.fitted_rates.push_back(a.drifts[k].rate);
      const double fitted = a.drifts[k].rate;
      const auto c = static_cast<Eigen::Index>(index_of(model.layout.y_names, a.drifts[k].channel));
      double best_rate = fitted, best_rmse = std::numeric_limits<double>::infinity();
      for (int step = 0; step <= 50; ++step) {
        a.drifts[k].rate = fitted * 0.1 * step;
        probe.sensor = sensor_after(model.sensor, a);
        std::vector<HeldOutLog> train = eval_logs(probe, before_pbs);
        for (std::size_t i = 0; i < train.size(); ++i) {
          train[i].end = train[i].first;
          train[i].first = ResidualLog::kFirstRow + d;
        }
        const double rmse = held_out_error(probe, train).rmse(c);
        if (rmse < best_rmse) best_rmse = rmse, best_rate = a.drifts[k].rate;
      }
      a.drifts[k].rate = best_rate;
    }
    char text[64];
    std::string rates;
    for (const SensorDrift& drift : a.drifts) {
      std::snprintf(text, sizeof text, "%s%s %.4g", rates.empty() ? "" : ", ", drift.channel.c_str(), drift.rate);
      rates += text;
    }
    a.description += "; rates re-estimated: " + rates;
  }

  // Training parts: raw rows [0, first) in the measured frame; a frame
  // aligned by a delay of s rows holds them in rows [0, first - s).
  auto training_part = [&](const SensorModel& sensor, const FeatureLayout& layout) {
    const std::vector<LogInput> src = model_frame_logs(sensor, logs);
    std::vector<LogSequence> seqs;
    for (std::size_t i = 0; i < src.size(); ++i) {
      LogSequence s = log_sequence(src[i].table, src[i].file, layout);
      const int keep = split[i] - sensor.max_delay();
      s.y = s.y.leftCols(keep).eval();
      s.u = s.u.leftCols(keep).eval();
      seqs.push_back(std::move(s));
    }
    return seqs;
  };

  if (options.control) {
    HadynetModel c = model;
    const auto seqs = training_part(c.sensor, c.layout);
    const auto rows = ensure_states(c, seqs, before_pbs);
    fine_tune(c, seqs, rows, tuning, nullptr);
    result.control = held_out_error(c, eval_logs(c, state_pbs(c)));
  }

  // The augmented layout first (aux adds a channel, friction commands), then its training data.
  const auto seqs = training_part(sensor_after(model.sensor, *aug), augmented_layout(model.layout, *aug));
  HadynetModel after = augmented_model(model, *aug, seqs);
  const auto rows = ensure_states(after, seqs, before_pbs);
  result.loss_history = fine_tune(after, seqs, rows, tuning, &result.train_windows);
  after.check_consistent();
  result.after = held_out_error(after, eval_logs(after, state_pbs(after)));

  // The residual analysis of the augmented model (in its own frame).
  ResidualData again = compute_residuals(after, logs, "state");
  // An aux column the model now predicts is no longer an unused channel.
  for (std::size_t a = again.aux_names.size(); a-- > 0;) {
    if (index_of(again.y_names, again.aux_names[a]) < 0) continue;
    again.aux_names.erase(again.aux_names.begin() + static_cast<std::ptrdiff_t>(a));
    for (auto& log : again.logs) {
      Eigen::MatrixXd kept(log.aux.rows() - 1, log.aux.cols());
      kept << log.aux.topRows(static_cast<Eigen::Index>(a)),
          log.aux.bottomRows(log.aux.rows() - 1 - static_cast<Eigen::Index>(a));
      log.aux = kept;
    }
  }
  LibraryOptions lib;
  result.after.verdict = verdict_text(attribute(again, enumerate_hypotheses(again, lib), attribution.options));
  result.tried = true;

  // The decision: after against the reference on the channels the
  // augmentation changes (of the model's own channels): the aligned, cleaned,
  // clipped, drifting or friction channels; for an aux channel, the channels
  // its significant hypotheses explain.
  const auto add_channel = [&](const std::string& name) {
    if (index_of(model.layout.y_names, name) < 0) return;
    if (std::find(result.confirmation_channels.begin(), result.confirmation_channels.end(), name) ==
        result.confirmation_channels.end())
      result.confirmation_channels.push_back(name);
  };
  if (aug->kind == EffectKind::kAuxChannel) {
    const int source = index_of(data.aux_names, aug->channels.at(0));
    for (const auto& r : attribution.ranked)
      if (r.significant && r.hypothesis.kind == EffectKind::kAuxChannel && r.hypothesis.source == source)
        add_channel(data.y_names[static_cast<std::size_t>(r.hypothesis.target)]);
  } else {
    for (const auto& name : aug->channels) add_channel(name);
  }
  const HeldOutError& reference = result.control ? *result.control : result.before;
  result.reference = result.control ? "fine-tuning alone" : "the unchanged model";
  result.confirmation = diebold_mariano(standardised_loss(model, reference, result.confirmation_channels),
                                        standardised_loss(model, result.after, result.confirmation_channels));
  const bool confirmed = result.confirmation.mean > 0 && result.confirmation.p_value < attribution.options.alpha;
  char p[32];
  std::snprintf(p, sizeof p, "%.2g", result.confirmation.p_value);
  if (!confirmed) {
    result.status = "unexplained structure: adding " + aug->effect + " (" + aug->description + ") did not beat " +
                    result.reference + " on the held-out rows of the channels it was found on (Diebold-Mariano p " +
                    p + ")";
    return result;
  }
  result.model = std::move(after);
  result.changed = true;
  result.status = "fixed";
  return result;
}

}  // namespace hadynet::trainer::residual
