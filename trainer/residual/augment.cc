#include "trainer/residual/augment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "trainer/deploy_prep.h"
#include "trainer/hadynet_network.h"
#include "trainer/optim.h"
#include "trainer/training.h"
#include "trainer/window_dataset.h"

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

// Adds a PB row for every state of `seqs` the model does not know, starting
// from the PB the analysis used for that state's logs; returns each
// sequence's row.
std::vector<int> ensure_states(HadynetModel& model, const std::vector<LogSequence>& seqs,
                               const std::vector<Eigen::VectorXf>& pb_of_seq) {
  std::vector<int> rows;
  for (std::size_t i = 0; i < seqs.size(); ++i) {
    int k = model.state_index(seqs[i].state);
    if (k < 0) {
      k = static_cast<int>(model.states.size());
      model.states.push_back({seqs[i].state, seqs[i].object});
      model.params.pb.conservativeResize(k + 1, model.params.dims.pb);
      model.params.pb.row(k) = pb_of_seq[i].transpose();
      model.params.dims.states = k + 1;
    }
    rows.push_back(k);
  }
  return rows;
}

// Fine-tunes `model` on every window of `seqs` with batch norm frozen (eval
// mode: the running statistics of the original training data stay; with a
// few hundred windows, batch statistics would move them and hurt every
// channel); Adam on every weight and the PB table, the window order of
// epoch_order(seed, epoch). Returns the loss per epoch and the number of
// windows; re-measures the value ranges on those windows.
std::vector<double> fine_tune(HadynetModel& model, const std::vector<LogSequence>& seqs,
                              const std::vector<int>& state_rows, const FixOptions& o, long* windows) {
  const WindowDataset data(seqs, state_rows, model.layout, model.norm, model.train_steps);
  std::vector<int> ids(static_cast<std::size_t>(data.size()));
  std::iota(ids.begin(), ids.end(), 0);
  if (ids.size() < 2) throw std::runtime_error("--fix: the training part of the logs holds fewer than 2 windows");
  Adam<float> adam(Adam<float>::Options{o.lr, 0.9, 0.999, 1e-8}, GroupSet::all().without(ParamGroup::kEncoderBn));
  HadynetNetwork<float> net;
  HadynetGrads<float> grads;
  WindowBatch<float> batch;
  Matrix<float> y, d_y;
  std::vector<double> history;
  const auto batch_size = static_cast<std::size_t>(std::max(1, o.batch));
  for (int epoch = 1; epoch <= o.epochs; ++epoch) {
    const std::vector<int> order = epoch_order(ids, o.seed, epoch);
    double sum = 0;
    int batches = 0;
    for (std::size_t begin = 0; begin < order.size(); begin += batch_size) {
      const std::size_t n = std::min(batch_size, order.size() - begin);
      data.gather(std::span<const int>(order).subspan(begin, n), batch, y);
      const Matrix<float>& y_hat = net.forward(model.params, batch, BnMode::kEval);
      sum += static_cast<double>(mse_loss(y_hat, y, &d_y));
      net.backward(model.params, d_y, grads);
      adam.step(model.params, grads.params);
      ++batches;
    }
    history.push_back(sum / batches);
    if (!std::isfinite(history.back())) throw std::runtime_error("--fix: fine-tuning diverged (loss not finite)");
  }
  ValueRanges ranges = measure_ranges(model, data, ids);
  ranges.source = "hadynet residual --fix: training part of " + std::to_string(seqs.size()) + " logs";
  model.ranges = ranges;
  model.detection.reset();  // calibrated with the old weights
  if (windows != nullptr) *windows = static_cast<long>(ids.size());
  return history;
}

// How the model's frame maps to the measured channels (see the header).
struct OutputMap {
  std::vector<bool> delayed;  // per y channel: reported d steps late
  int d = 0;
  int xt_target = -1, xt_source = -1;  // crosstalk: measured y_c = y'_c + gain y_s
  double gain = 0;
};

// Physical predictions of the measured rows of one log (y x T_raw, NaN where
// there is none): see the header for the frame and the d + 1 steps.
Eigen::MatrixXd measured_predictions(const HadynetModel& model, const LogSequence& frame, const Eigen::VectorXf& pb,
                                     const OutputMap& map, int rows_raw) {
  const std::vector<bool>& delayed = map.delayed;
  const int d = map.d;
  const Eigen::MatrixXd p = predict_windows(model, frame, pb, d + 1);
  const Eigen::Index B = p.cols() / (d + 1);
  Eigen::MatrixXd out = Eigen::MatrixXd::Constant(p.rows(), rows_raw, std::numeric_limits<double>::quiet_NaN());
  for (int t = d + 2; t < rows_raw; ++t) {
    const Eigen::Index b = t - d - 2;  // window starting at frame row t - d - 1
    if (b >= B) break;
    for (Eigen::Index c = 0; c < p.rows(); ++c) {
      const Eigen::Index k = delayed[static_cast<std::size_t>(c)] ? 0 : d;
      out(c, t) = p(c, k * B + b);
    }
    if (map.xt_target >= 0) out(map.xt_target, t) += map.gain * p(map.xt_source, b);
  }
  return out;
}

struct EvalLog {
  LogSequence measured;  // raw log in the model's layout
  LogSequence frame;     // the log in the model's frame (aligned for a delay)
  Eigen::VectorXf pb;
  int first = 0, end = 0;  // held-out rows [first, end)
};

HeldOutError held_out_error(const HadynetModel& model, const std::vector<EvalLog>& logs, const OutputMap& map) {
  HeldOutError e;
  e.channels = model.layout.y_names;
  const auto ny = static_cast<Eigen::Index>(e.channels.size());
  const auto nu = static_cast<Eigen::Index>(model.layout.u_names.size());
  Eigen::VectorXd sum_y = Eigen::VectorXd::Zero(ny), sum_yy = sum_y, sum_ee = sum_y;
  std::vector<Segments> res(static_cast<std::size_t>(ny)), inp(static_cast<std::size_t>(nu));
  for (const auto& log : logs) {
    const Eigen::MatrixXd p = measured_predictions(model, log.frame, log.pb, map, log.measured.steps());
    const int n = log.end - log.first;
    const Eigen::MatrixXd y = log.measured.y.middleCols(log.first, n);
    const Eigen::MatrixXd r = y - p.middleCols(log.first, n);
    if (!r.allFinite()) throw std::logic_error("--fix: a held-out row has no prediction");
    const Eigen::MatrixXd yc = y.colwise() - model.norm.y.mean;  // shifted: no cancellation
    sum_y += yc.rowwise().sum();
    sum_yy += yc.array().square().matrix().rowwise().sum();
    sum_ee += r.array().square().matrix().rowwise().sum();
    e.samples += n;
    for (Eigen::Index c = 0; c < ny; ++c) res[static_cast<std::size_t>(c)].push_back(r.row(c).transpose());
    for (Eigen::Index j = 0; j < nu; ++j)
      inp[static_cast<std::size_t>(j)].push_back(log.measured.u.row(j).segment(log.first, n).transpose());
  }
  const double n = static_cast<double>(e.samples);
  e.rmse.resize(ny);
  e.fit.resize(ny);
  for (Eigen::Index c = 0; c < ny; ++c) {
    const double ss_total = sum_yy(c) - sum_y(c) * sum_y(c) / n;
    e.rmse(c) = std::sqrt(sum_ee(c) / n);
    e.fit(c) = ss_total > 0 ? 100.0 * (1.0 - std::sqrt(sum_ee(c) / ss_total)) : 0.0;
    const auto& rc = res[static_cast<std::size_t>(c)];
    e.whiteness.push_back(whiteness(rc, kDefaultMaxLag));
    int outside = 0;
    for (const auto& u : inp) outside += cross_correlate(rc, u, kDefaultMaxLag).outside;
    e.inputs_outside.push_back(outside);
  }
  return e;
}

std::string verdict_of(const Attribution& a) {
  const auto w = a.winner();
  return w ? w->effect + ": " + w->label : "no significant effect";
}

}  // namespace

bool fix_supported(EffectKind kind) {
  return kind == EffectKind::kSensorDelay || kind == EffectKind::kAuxChannel || kind == EffectKind::kCrosstalk;
}

std::optional<Augmentation> plan_augmentation(const ResidualData& data, const Attribution& attribution) {
  const auto w = attribution.winner();
  if (!w) return std::nullopt;
  Augmentation a;
  a.kind = w->hypothesis.kind;
  a.effect = w->effect;
  const auto& h = w->hypothesis;
  switch (h.kind) {
    case EffectKind::kSensorDelay:
      a.delay = h.delay;
      for (const auto& r : attribution.winner_family())
        if (r.hypothesis.delay == h.delay) a.channels.push_back(data.y_names[static_cast<std::size_t>(r.hypothesis.target)]);
      a.description = "time-align " + join(a.channels) + " by " + std::to_string(a.delay) +
                      " steps (the model predicts the true-time signal; output_delay restores the sensor's)";
      break;
    case EffectKind::kAuxChannel:
      a.channels = {data.aux_names[static_cast<std::size_t>(h.source)]};
      a.description = "use " + a.channels[0] + " as an observed channel (input of x, predicted in y)";
      break;
    case EffectKind::kCrosstalk: {
      a.channels = {data.y_names[static_cast<std::size_t>(h.target)]};
      a.source = data.y_names[static_cast<std::size_t>(h.source)];
      a.gain = w->parameter;
      char gain[32];
      std::snprintf(gain, sizeof gain, "%.4g", a.gain);
      a.description = "remove the crosstalk " + a.source + " -> " + a.channels[0] + " (train on " + a.channels[0] +
                      " - " + gain + " " + a.source + "; output_crosstalk adds it back)";
      break;
    }
    default:
      a.description = effect_info(h.kind).augmentation;
      break;
  }
  return a;
}

namespace {

// The crosstalk frame: the target column minus gain times the source column, every row.
std::vector<LogInput> crosstalk_removed(const std::vector<LogInput>& logs, const Augmentation& a) {
  std::vector<LogInput> out = logs;
  for (auto& in : out) {
    auto& t = in.table;
    const auto c = t.column_index(a.channels.at(0));
    const auto s = t.column_index(a.source);
    if (!c || !s) throw std::runtime_error(in.file + ": no column '" + (c ? a.source : a.channels.at(0)) + "'");
    const std::size_t cols = t.columns.size();
    for (std::size_t r = 0; r < t.rows(); ++r) t.values[r * cols + *c] -= a.gain * t.values[r * cols + *s];
  }
  return out;
}

}  // namespace

std::vector<LogInput> augmented_logs(const std::vector<LogInput>& logs, const Augmentation& a) {
  if (a.kind == EffectKind::kCrosstalk) return crosstalk_removed(logs, a);
  if (a.kind != EffectKind::kSensorDelay || a.delay == 0) return logs;
  std::vector<LogInput> out;
  for (const auto& in : logs) {
    const auto& t = in.table;
    const std::size_t T = t.rows(), cols = t.columns.size(), d = static_cast<std::size_t>(a.delay);
    if (T <= d) throw std::runtime_error(in.file + ": fewer rows than the delay");
    std::vector<bool> shifted(cols, false);
    for (const auto& name : a.channels) {
      const auto c = t.column_index(name);
      if (!c) throw std::runtime_error(in.file + ": no column '" + name + "'");
      shifted[*c] = true;
    }
    LogInput aligned{datalog::LogTable{}, in.file};
    aligned.table.metadata = t.metadata;
    aligned.table.columns = t.columns;
    aligned.table.values.reserve((T - d) * cols);
    for (std::size_t r = 0; r + d < T; ++r)
      for (std::size_t c = 0; c < cols; ++c) aligned.table.values.push_back(t.at(shifted[c] ? r + d : r, c));
    out.push_back(std::move(aligned));
  }
  return out;
}

HadynetModel augmented_model(const HadynetModel& model, const Augmentation& a,
                             const std::vector<LogSequence>& train_seqs) {
  HadynetModel m = model;
  m.detection.reset();
  m.ranges.reset();
  m.provenance["residual_fix"] = a.effect + ": " + a.description;
  if (a.kind == EffectKind::kSensorDelay) {
    m.provenance["output_delay"] = join(a.channels) + ": " + std::to_string(a.delay) + " steps";
    return m;
  }
  if (a.kind == EffectKind::kCrosstalk) {
    char gain[32];
    std::snprintf(gain, sizeof gain, "%.6g", a.gain);
    m.provenance["output_crosstalk"] = a.channels.at(0) + " += " + gain + " * " + a.source +
                                       " (inputs: " + a.channels.at(0) + " -= " + gain + " * " + a.source + ")";
    return m;
  }
  if (a.kind != EffectKind::kAuxChannel) throw std::invalid_argument("--fix: " + a.effect + " is not implemented");
  const std::string& aux = a.channels.at(0);
  std::vector<std::string> y = model.layout.y_names;
  y.push_back(aux);
  m.layout = feature_layout_from_names(y, model.layout.u_names, model.layout.delta_groups);
  // The aux group is last in y and not a delta group, so it is the last x channel.
  if (m.layout.x_names.back() != aux || m.layout.x_names.size() != model.layout.x_names.size() + 1)
    throw std::logic_error("--fix: unexpected x layout for " + aux);
  // Standardisation of the new channel over the training rows (population std).
  double sum = 0, sum_sq = 0;
  long n = 0;
  const auto row = static_cast<Eigen::Index>(y.size() - 1);
  for (const auto& s : train_seqs) {
    if (s.y.rows() != row + 1) throw std::invalid_argument("--fix: training logs lack " + aux);
    sum += s.y.row(row).sum();
    sum_sq += s.y.row(row).squaredNorm();
    n += s.steps();
  }
  if (n == 0) throw std::invalid_argument("--fix: no training rows");
  const double mean = sum / static_cast<double>(n);
  double sd = std::sqrt(std::max(0.0, sum_sq / static_cast<double>(n) - mean * mean));
  if (!(sd > 0)) sd = 1.0;
  auto append = [](Eigen::VectorXd& v, double value) {
    v.conservativeResize(v.size() + 1);
    v(v.size() - 1) = value;
  };
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
  const int d = aug != nullptr ? aug->delay : 0;

  // Held-out rows of each log: [first, end), the same for every model.
  std::vector<int> split;
  for (const auto& in : logs) {
    const int T = static_cast<int>(in.table.rows());
    const int first = std::max(static_cast<int>(std::floor(options.train_fraction * T)), d + 2);
    if (first >= T - d) throw std::runtime_error(in.file + ": too short for --fix's time split");
    split.push_back(first);
  }
  auto eval_logs = [&](const HadynetModel& m, const std::vector<LogInput>& frame_logs,
                       const std::vector<Eigen::VectorXf>& pbs) {
    std::vector<EvalLog> out;
    for (std::size_t i = 0; i < logs.size(); ++i) {
      EvalLog e;
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
  std::vector<Eigen::VectorXf> before_pbs;
  for (const auto& log : data.logs) before_pbs.push_back(log.pb);
  OutputMap none;
  none.delayed.assign(model.layout.y_names.size(), false);
  result.before = held_out_error(model, eval_logs(model, logs, before_pbs), none);
  result.before.verdict = verdict_of(attribution);

  if (aug == nullptr) {
    result.status = "no significant effect";
    return result;
  }
  if (!fix_supported(aug->kind)) {
    result.status = "not supported: " + aug->effect + " (planned: " + aug->description + ")";
    return result;
  }

  // Training parts: raw rows [0, first) in the measured frame; the aligned frame
  // holds them in rows [0, first - d).
  const std::vector<LogInput> frame_logs = augmented_logs(logs, *aug);
  auto training_part = [&](const std::vector<LogInput>& src, const FeatureLayout& layout, int shift) {
    std::vector<LogSequence> seqs;
    for (std::size_t i = 0; i < src.size(); ++i) {
      LogSequence s = log_sequence(src[i].table, src[i].file, layout);
      const int keep = split[i] - shift;
      s.y = s.y.leftCols(keep).eval();
      s.u = s.u.leftCols(keep).eval();
      seqs.push_back(std::move(s));
    }
    return seqs;
  };

  if (options.control) {
    HadynetModel c = model;
    const auto seqs = training_part(logs, c.layout, 0);
    const auto rows = ensure_states(c, seqs, before_pbs);
    fine_tune(c, seqs, rows, options, nullptr);
    result.control = held_out_error(c, eval_logs(c, logs, state_pbs(c)), none);
  }

  // The augmented layout first (aux adds a channel), then its training data.
  FeatureLayout layout = model.layout;
  if (aug->kind == EffectKind::kAuxChannel) {
    std::vector<std::string> y = layout.y_names;
    y.push_back(aug->channels.at(0));
    layout = feature_layout_from_names(y, layout.u_names, layout.delta_groups);
  }
  const auto seqs = training_part(frame_logs, layout, d);
  HadynetModel after = augmented_model(model, *aug, seqs);
  const auto rows = ensure_states(after, seqs, before_pbs);
  result.loss_history = fine_tune(after, seqs, rows, options, &result.train_windows);
  after.check_consistent();

  OutputMap map;
  map.delayed.assign(after.layout.y_names.size(), false);
  map.d = d;
  for (const auto& name : aug->channels) {
    const int c = index_of(after.layout.y_names, name);
    if (c >= 0 && aug->kind == EffectKind::kSensorDelay) map.delayed[static_cast<std::size_t>(c)] = true;
  }
  if (aug->kind == EffectKind::kCrosstalk) {
    map.xt_target = index_of(after.layout.y_names, aug->channels.at(0));
    map.xt_source = index_of(after.layout.y_names, aug->source);
    if (map.xt_target < 0 || map.xt_source < 0) throw std::logic_error("--fix: crosstalk channels not in the model");
    map.gain = aug->gain;
  }
  result.after = held_out_error(after, eval_logs(after, frame_logs, state_pbs(after)), map);
  // The residual analysis of the augmented model in its own frame.
  ResidualData again = compute_residuals(after, frame_logs, "state");
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
  result.after.verdict = verdict_of(attribute(again, enumerate_hypotheses(again, lib), attribution.options));
  result.model = std::move(after);
  result.changed = true;
  result.status = "fixed";
  return result;
}

}  // namespace hadynet::trainer::residual
