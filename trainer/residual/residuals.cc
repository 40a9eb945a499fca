#include "trainer/residual/residuals.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <span>
#include <stdexcept>

#include "datalog/robot_profile.h"
#include "trainer/hadynet_network.h"
#include "trainer/model_frame.h"
#include "trainer/output_clip.h"
#include "trainer/pb_adaptation.h"
#include "trainer/training.h"
#include "trainer/window_dataset.h"

namespace hadynet::trainer::residual {

namespace {

double parse_number(const std::string& text, const std::string& what) {
  double v = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || ptr != end) throw std::runtime_error(what + ": expected a number, got '" + text + "'");
  return v;
}

Eigen::VectorXf adapt_to(const HadynetModel& model, const std::vector<LogSequence>& seqs) {
  const WindowDataset data(seqs, std::vector<int>(seqs.size(), 0), model.layout, model.norm, model.train_steps);
  if (data.size() == 0) {
    throw std::runtime_error("state '" + seqs.front().state + "': logs too short for one window of " +
                             std::to_string(model.train_steps) + " steps");
  }
  std::vector<int> ids(static_cast<std::size_t>(data.size()));
  std::iota(ids.begin(), ids.end(), 0);
  return adapt_pb(model, data, ids, Eigen::VectorXf::Zero(model.params.dims.pb), AdaptOptions{}).pb;
}

// --pb auto on a state the model was trained on. A state's name is a
// label: a real hand re-zeroed at start-up, or worn since training, keeps its
// name and changes its dynamics. So the trained PB is checked: a PB is adapted
// to the first 70 % of the state's windows and both are scored on the last
// 30 % (WindowDataset::split_tail: no observation in both). The trained PB is
// replaced (by a PB adapted to all the windows) only when it predicts a
// typical channel's held-out rows worse by more than kStoredPbMargin
// (StoredPbCheck::channel_ratio).
constexpr double kCheckHeldOutFraction = 0.3;

StoredPbCheck check_stored_pb(const HadynetModel& model, const std::vector<LogSequence>& seqs,
                              const Eigen::VectorXf& stored) {
  const WindowDataset data(seqs, std::vector<int>(seqs.size(), 0), model.layout, model.norm, model.train_steps);
  const WindowDataset::Split split = data.split_tail(kCheckHeldOutFraction);
  StoredPbCheck c;
  if (split.train.empty() || split.held_out.empty()) return c;
  const Eigen::VectorXf adapted =
      adapt_pb(model, data, split.train, Eigen::VectorXf::Zero(model.params.dims.pb), AdaptOptions{}).pb;
  c.checked = true;
  c.stored_channel_loss = evaluate_channel_loss(model, data, split.held_out, stored);
  c.adapted_channel_loss = evaluate_channel_loss(model, data, split.held_out, adapted);
  c.stored_loss = c.stored_channel_loss.mean();
  c.adapted_loss = c.adapted_channel_loss.mean();
  // A channel both PBs predict exactly (a constant one) has ratio 1: tiny is
  // relative to the whole loss, so no channel's units matter.
  const double tiny = 1e-12 * (c.stored_loss + c.adapted_loss) + std::numeric_limits<double>::min();
  c.channel_ratio = std::exp(((c.stored_channel_loss.array() + tiny) / (c.adapted_channel_loss.array() + tiny))
                                 .log()
                                 .mean());
  c.replace = c.channel_ratio > kStoredPbMargin;
  return c;
}

std::string loss_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// An explicit PB: "zero", a state of the model, or comma-separated numbers.
Eigen::VectorXf explicit_pb(const HadynetModel& model, const std::string& text) {
  const int d = model.params.dims.pb;
  if (text == "zero") return Eigen::VectorXf::Zero(d);
  if (const int k = model.state_index(text); k >= 0) return model.params.pb.row(k).transpose();
  std::vector<float> v;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    v.push_back(static_cast<float>(parse_number(text.substr(start, comma - start), "PB '" + text + "'")));
    start = comma + 1;
  }
  if (static_cast<int>(v.size()) != d) {
    throw std::runtime_error("PB '" + text + "': not zero, auto, state, adapt, a state of the model or " +
                             std::to_string(d) + " comma-separated numbers");
  }
  return Eigen::Map<Eigen::VectorXf>(v.data(), d);
}

}  // namespace

std::vector<std::string> common_aux_names(const std::vector<LogInput>& logs) {
  std::vector<std::string> names;
  if (logs.empty()) return names;
  for (const auto& c : logs.front().table.columns)
    if (c.rfind("aux_", 0) == 0) names.push_back(c);
  std::erase_if(names, [&](const std::string& n) {
    return std::any_of(logs.begin(), logs.end(),
                       [&](const LogInput& l) { return !l.table.column_index(n).has_value(); });
  });
  return names;
}

namespace {

// Windows per network call: bounds the forward pass's activations (they grow
// with windows x steps; 40 000 windows of 50 steps at once took 8 GB).
constexpr int kWindowChunk = 256;

// Predictions of the windows `ids` of `data`, laid out as predict_windows()
// documents for ids.size() windows (step-major). `net` is reused across
// chunks (its buffers keep their size).
Eigen::MatrixXd predict_window_ids(HadynetNetwork<float>& net, const HadynetModel& model, const WindowDataset& data,
                                   const Eigen::VectorXf& pb, std::span<const int> ids) {
  WindowBatch<float> batch;
  Matrix<float> target;
  data.gather(ids, batch, target);
  batch.pb = pb.replicate(1, static_cast<Eigen::Index>(ids.size()));
  Eigen::MatrixXd y = net.forward(model.params, batch, BnMode::kEval).cast<double>();
  y = (y.array().colwise() * model.norm.y.std.array()).colwise() + model.norm.y.mean.array();
  apply_output_clips(model, y);
  return y;
}

// The windows [first, first + count) of `data`.
Eigen::MatrixXd predict_window_range(HadynetNetwork<float>& net, const HadynetModel& model, const WindowDataset& data,
                                     const Eigen::VectorXf& pb, int first, int count) {
  std::vector<int> ids(static_cast<std::size_t>(count));
  std::iota(ids.begin(), ids.end(), first);
  return predict_window_ids(net, model, data, pb, ids);
}

}  // namespace

Eigen::MatrixXd predict_windows(const HadynetModel& model, const LogSequence& seq, const Eigen::VectorXf& pb,
                                int steps) {
  const WindowDataset data({seq}, {0}, model.layout, model.norm, steps);
  const int B = data.size();
  Eigen::MatrixXd out(model.params.dims.y, static_cast<Eigen::Index>(B) * steps);
  HadynetNetwork<float> net;
  for (int first = 0; first < B; first += kWindowChunk) {
    const int count = std::min(kWindowChunk, B - first);
    const Eigen::MatrixXd y = predict_window_range(net, model, data, pb, first, count);
    for (int k = 0; k < steps; ++k)
      out.middleCols(static_cast<Eigen::Index>(k) * B + first, count) = y.middleCols(static_cast<Eigen::Index>(k) * count, count);
  }
  return out;
}

Eigen::MatrixXd predict_windows_from(const HadynetModel& model, const LogSequence& seq, const Eigen::VectorXf& pb,
                                     int steps, const std::vector<int>& starts) {
  const WindowDataset data({seq}, {0}, model.layout, model.norm, steps);
  const auto n = static_cast<int>(starts.size());
  Eigen::MatrixXd out(model.params.dims.y, static_cast<Eigen::Index>(n) * steps);
  HadynetNetwork<float> net;
  for (int first = 0; first < n; first += kWindowChunk) {
    const int count = std::min(kWindowChunk, n - first);
    std::vector<int> ids;  // window b starts from row b + 1
    for (int i = first; i < first + count; ++i) {
      const int s = starts[static_cast<std::size_t>(i)];
      if (s < 1 || s - 1 >= data.size()) throw std::logic_error("predict_windows_from: a window starts outside the log");
      ids.push_back(s - 1);
    }
    const Eigen::MatrixXd y = predict_window_ids(net, model, data, pb, ids);
    for (int i = 0; i < count; ++i)
      for (int k = 0; k < steps; ++k)
        out.col(static_cast<Eigen::Index>(first + i) * steps + k) = y.col(static_cast<Eigen::Index>(k) * count + i);
  }
  return out;
}

std::vector<std::string> channel_units(const std::string& units_text, const std::vector<std::string>& names) {
  std::vector<std::string> out;
  for (const auto& name : names) {
    std::string unit = datalog::declared_unit(units_text, name);
    out.push_back(unit.empty() ? datalog::declared_unit(units_text, channel_group(name)) : unit);
  }
  return out;
}

std::vector<bool> channels_in_groups(const std::vector<std::string>& u_names, const std::vector<std::string>& groups) {
  std::vector<bool> out;
  for (const auto& name : u_names)
    out.push_back(std::find(groups.begin(), groups.end(), channel_group(name)) != groups.end());
  return out;
}

ResidualData compute_residuals(const HadynetModel& model, const std::vector<LogInput>& logs,
                               const std::string& pb_choice) {
  if (logs.empty()) throw std::runtime_error("no logs");
  ResidualData data;
  data.y_names = model.layout.y_names;
  data.u_names = model.layout.u_names;
  data.y_units = channel_units(logs.front().table.metadata.get("units").value_or(""), data.y_names);
  try {
    data.u_absolute = channels_in_groups(
        data.u_names, datalog::split_list(logs.front().table.metadata.get("absolute_groups").value_or("")));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(logs.front().file + ": metadata 'absolute_groups': " + e.what());
  }
  data.aux_names = common_aux_names(logs);
  data.y_scale = model.norm.y.std;
  for (const std::string& name : data.y_names) data.y_frame_transformed.push_back(frame_transforms(model.sensor, name));
  data.crosstalk = model.sensor.crosstalk;

  for (const auto& raw : logs) {
    // The model sees (and predicts) its own frame; the aux columns are read from the same rows.
    ModelFrameLog in = in_model_frame(model.sensor, model.layout, raw.table, raw.file);
    ResidualLog log;
    log.seq = std::move(in.sequence);
    if (log.seq.steps() < ResidualLog::kFirstRow + 1 + model.train_steps) {
      throw std::runtime_error(raw.file + ": " + std::to_string(log.seq.steps()) + " rows; at least " +
                               std::to_string(ResidualLog::kFirstRow + 1 + model.train_steps) + " needed");
    }
    log.dt_s = log_dt(in.table, raw.file);
    const auto T = static_cast<Eigen::Index>(in.table.rows());
    log.aux.resize(static_cast<Eigen::Index>(data.aux_names.size()), T);
    for (std::size_t a = 0; a < data.aux_names.size(); ++a) {
      const std::size_t col = *in.table.column_index(data.aux_names[a]);
      for (Eigen::Index t = 0; t < T; ++t)
        log.aux(static_cast<Eigen::Index>(a), t) = in.table.at(static_cast<std::size_t>(t), col);
    }
    data.logs.push_back(std::move(log));
  }

  // PB per log; adaptation runs once per state over all of that state's logs.
  std::map<std::string, std::vector<std::size_t>> by_state;
  for (std::size_t i = 0; i < data.logs.size(); ++i) by_state[data.logs[i].seq.state].push_back(i);
  for (const auto& [state, members] : by_state) {
    Eigen::VectorXf pb;
    std::string source;
    ResidualLog::PbOrigin origin = ResidualLog::PbOrigin::kGiven;
    const int k = model.state_index(state);
    if (pb_choice == "adapt" || (pb_choice == "auto" && k < 0)) {
      std::vector<LogSequence> seqs;
      for (std::size_t i : members) seqs.push_back(data.logs[i].seq);
      pb = adapt_to(model, seqs);
      source = "adapted to the state's logs";
      origin = ResidualLog::PbOrigin::kAdapted;
    } else if (pb_choice == "state" || pb_choice == "auto") {
      if (k < 0) {
        throw std::runtime_error(data.logs[members.front()].seq.file + ": state '" + state +
                                 "' is not in the model's PB table (use --pb adapt)");
      }
      pb = model.params.pb.row(k).transpose();
      source = "state " + state;
      origin = ResidualLog::PbOrigin::kTrained;
      if (pb_choice == "auto") {
        std::vector<LogSequence> seqs;
        for (std::size_t i : members) seqs.push_back(data.logs[i].seq);
        const StoredPbCheck check = check_stored_pb(model, seqs, pb);
        for (std::size_t i : members) data.logs[i].pb_check = check;
        const std::string losses = "held-out loss " + loss_text(check.stored_loss) + " trained, " +
                                   loss_text(check.adapted_loss) + " adapted; per channel trained/adapted " +
                                   loss_text(check.channel_ratio) + " (geometric mean)";
        if (check.replace) {
          pb = adapt_to(model, seqs);
          source = "adapted to the state's logs: the trained PB of " + state + " fits them worse (" + losses +
                   "; margin " + loss_text(kStoredPbMargin) + ")";
          origin = ResidualLog::PbOrigin::kAdaptedOverTrained;
        } else if (check.checked) {
          source = "state " + state + " (checked: " + losses + ")";
        } else {
          source = "state " + state + " (not checked: too few windows to hold some out)";
        }
      }
    } else {
      pb = explicit_pb(model, pb_choice);
      source = pb_choice;
    }
    for (std::size_t i : members) {
      data.logs[i].pb = pb;
      data.logs[i].pb_source = source;
      data.logs[i].pb_origin = origin;
    }
  }

  for (auto& log : data.logs) {
    log.y_hat = predict_windows(model, log.seq, log.pb, 1);  // windows start at 1: rows 2..T-1
    log.r = log.seq.y.rightCols(log.y_hat.cols()) - log.y_hat;
  }
  return data;
}

HorizonMetrics horizon_metrics(const HadynetModel& model, const ResidualData& data, int horizon) {
  if (horizon < 1) throw std::invalid_argument("horizon must be >= 1");
  const auto ny = static_cast<Eigen::Index>(data.y_names.size());
  HorizonMetrics m;
  m.horizon = horizon;
  Eigen::MatrixXd sum_y = Eigen::MatrixXd::Zero(ny, horizon), sum_yy = sum_y, sum_ee = sum_y;
  // Window by window chunk, so memory does not grow with the log's length.
  HadynetNetwork<float> net;
  for (const auto& log : data.logs) {
    const WindowDataset windows({log.seq}, {0}, model.layout, model.norm, horizon);
    const int B = windows.size();
    m.samples += B;
    for (int first = 0; first < B; first += kWindowChunk) {
      const int count = std::min(kWindowChunk, B - first);
      const Eigen::MatrixXd y_hat = predict_window_range(net, model, windows, log.pb, first, count);
      for (int k = 0; k < horizon; ++k) {
        // Window b starts at row b + 1 and predicts row b + 1 + k + 1 at step k.
        const Eigen::MatrixXd y_phys = log.seq.y.middleCols(first + k + 2, count);
        const Eigen::MatrixXd e = y_phys - y_hat.middleCols(static_cast<Eigen::Index>(k) * count, count);
        // Sums of y - (training mean): the shift keeps ||y - mean(y)||^2 free of cancellation.
        const Eigen::MatrixXd y = y_phys.colwise() - model.norm.y.mean;
        sum_y.col(k) += y.rowwise().sum();
        sum_yy.col(k) += y.array().square().matrix().rowwise().sum();
        sum_ee.col(k) += e.array().square().matrix().rowwise().sum();
      }
    }
  }
  const double n = static_cast<double>(m.samples);
  m.fit.resize(ny, horizon);
  m.rmse.resize(ny, horizon);
  for (Eigen::Index c = 0; c < ny; ++c) {
    for (int k = 0; k < horizon; ++k) {
      const double ss_total = sum_yy(c, k) - sum_y(c, k) * sum_y(c, k) / n;  // ||y - mean(y)||^2
      m.rmse(c, k) = n > 0 ? std::sqrt(sum_ee(c, k) / n) : 0.0;
      m.fit(c, k) = ss_total > 0 ? 100.0 * (1.0 - std::sqrt(sum_ee(c, k) / ss_total)) : 0.0;
    }
  }
  return m;
}

}  // namespace hadynet::trainer::residual
