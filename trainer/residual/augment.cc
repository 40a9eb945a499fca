#include "trainer/residual/augment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "trainer/model_frame.h"
#include "trainer/residual/analysis.h"

namespace hadynet::trainer::residual {

namespace {

int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
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

bool fix_supported(EffectKind kind) { return effect_info(kind).plan != nullptr; }

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
  effect_info(a.kind).plan(data, attribution, *w, a);
  if (w->label != winner->label)
    a.description = "the winner (" + winner->effect + ": " + winner->label +
                    ") has no augmentation; the best significant effect that has: " + w->label + "; " + a.description;
  return a;
}

SensorModel sensor_after(const SensorModel& before, const Augmentation& a) {
  SensorModel s = before;
  std::visit([&](const auto& change) { change.add_to_sensor(s, a); }, a.change);
  return s;
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
    std::vector<HeldOutLog> out;
    for (std::size_t i = 0; i < logs.size(); ++i) {
      HeldOutLog e;
      e.raw = &logs[i];
      e.measured = log_sequence(logs[i].table, logs[i].file, m.layout);
      e.frame = in_model_frame(m.sensor, m.layout, logs[i].table, logs[i].file).sequence;
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

  // What the augmentation re-estimates on the training rows before
  // fine-tuning (drift: the rates), probing the unchanged network with a
  // sensor model.
  HadynetModel probe = model;
  const TrainingRmse training_rmse = [&](const SensorModel& sensor, const std::string& channel) {
    probe.sensor = sensor;
    std::vector<HeldOutLog> train = eval_logs(probe, before_pbs);
    for (std::size_t i = 0; i < train.size(); ++i) {
      train[i].end = train[i].first;
      train[i].first = ResidualLog::kFirstRow + d;
    }
    return held_out_error(probe, train).rmse(static_cast<Eigen::Index>(index_of(model.layout.y_names, channel)));
  };
  Augmentation& planned = *result.augmentation;
  std::visit([&](auto& change) { change.refine(planned, model.sensor, training_rmse, result.fitted_rates); },
             planned.change);

  // Training parts: raw rows [0, first) in the measured frame; a frame
  // aligned by a delay of s rows holds them in rows [0, first - s).
  auto training_part = [&](const SensorModel& sensor, const FeatureLayout& layout) {
    std::vector<LogSequence> seqs;
    for (std::size_t i = 0; i < logs.size(); ++i) {
      LogSequence s = in_model_frame(sensor, layout, logs[i].table, logs[i].file).sequence;
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

  // The decision: after against the reference on the channels the effect
  // was found on (the plan's found_on, of the model's own channels): the
  // aligned, cleaned, clipped, drifting or friction channels; for an aux
  // channel, the channels its significant hypotheses explain.
  for (const auto& name : aug->found_on) {
    if (index_of(model.layout.y_names, name) < 0) continue;
    if (std::find(result.confirmation_channels.begin(), result.confirmation_channels.end(), name) ==
        result.confirmation_channels.end())
      result.confirmation_channels.push_back(name);
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
