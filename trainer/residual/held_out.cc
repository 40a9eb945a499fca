#include "trainer/residual/held_out.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hadynet::trainer::residual {

namespace {

int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

// How the model's frame maps to the measured channels: its sensor model
// (sensor_model.h) by y row. The predictions clip the frame's estimate
// where the frame has a rail (output_clip.h); the measured value is clipped
// at the end, as the firmware reports it (cross-talk or drift may carry it
// past the rail).
struct OutputMap {
  std::vector<int> delay;  // per y channel: reported this many steps late
  int d = 0;               // the largest delay
  struct Crosstalk {
    Eigen::Index target, source;
    double gain;
  };
  std::vector<Crosstalk> crosstalk;                    // measured y_c = y'_c + gain y'_s
  std::vector<std::pair<Eigen::Index, SensorDrift>> drifts;  // measured y_c = y'_c + b_c
  std::vector<std::pair<Eigen::Index, SensorCurve>> curves;  // measured y_c = g_c(y'_c)
  std::vector<std::pair<Eigen::Index, OutputClip>> clips;     // measured y_c = clip_c(...)
};

OutputMap output_map(const HadynetModel& m) {
  const auto row = [&](const std::string& name) {
    const int c = index_of(m.layout.y_names, name);
    if (c < 0) throw std::logic_error("--fix: sensor model channel " + name + " not in the model");
    return static_cast<Eigen::Index>(c);
  };
  OutputMap map;
  map.delay.assign(m.layout.y_names.size(), 0);
  map.d = m.sensor.max_delay();
  for (const auto& x : m.sensor.delays) map.delay[static_cast<std::size_t>(row(x.channel))] = x.steps;
  for (const auto& x : m.sensor.crosstalk) map.crosstalk.push_back({row(x.target), row(x.source), x.gain});
  for (const auto& drift : m.sensor.drifts) map.drifts.emplace_back(row(drift.channel), drift);
  for (const auto& curve : m.sensor.curves) map.curves.emplace_back(row(curve.channel), curve);
  for (const auto& clip : m.sensor.clips) map.clips.emplace_back(row(clip.channel), clip);
  return map;
}

// Physical predictions of the measured rows of one log (y x T_raw, NaN where
// there is none): see the header for the frame and the d + 1 steps.
Eigen::MatrixXd measured_predictions(const HadynetModel& model, const LogSequence& frame, const Eigen::VectorXf& pb,
                                     const OutputMap& map, const LogInput& measured, int rows_raw) {
  const int d = map.d;
  const Eigen::MatrixXd p = predict_windows(model, frame, pb, d + 1);
  const Eigen::Index B = p.cols() / (d + 1);
  Eigen::MatrixXd out = Eigen::MatrixXd::Constant(p.rows(), rows_raw, std::numeric_limits<double>::quiet_NaN());
  for (int t = d + 2; t < rows_raw; ++t) {
    const Eigen::Index b = t - d - 2;  // window starting at frame row t - d - 1
    if (b >= B) break;
    for (Eigen::Index c = 0; c < p.rows(); ++c) {
      const Eigen::Index k = d - map.delay[static_cast<std::size_t>(c)];  // step predicting row t - delay_c
      out(c, t) = p(c, k * B + b);
    }
    for (const auto& [c, curve] : map.curves) out(c, t) = curve_reading(curve, out(c, t));
    for (const auto& x : map.crosstalk) out(x.target, t) += x.gain * p(x.source, b);
  }
  // Drift: the bias state is known up to row t - 1 from the measurements; its
  // last increment is estimated from the prediction itself (causal).
  const double dt = log_dt(measured.table, measured.file);
  for (const auto& [c, drift] : map.drifts) {
    const std::vector<double> driver = drift_driver(measured.table, measured.file, drift);
    for (int t = d + 2; t < rows_raw; ++t) {
      if (std::isnan(out(c, t))) continue;
      const double known = drift.rate * driver[static_cast<std::size_t>(t - 1)];
      // The level driver's step (SensorDrift): dt times the level's magnitude, the prediction's.
      const double increment = drift.load ? std::abs(out(c, t)) * dt : dt;
      out(c, t) += known + drift.rate * increment;
    }
  }
  for (const auto& [c, clip] : map.clips)
    for (int t = d + 2; t < rows_raw; ++t)
      if (clip.side > 0 ? out(c, t) > clip.rail : out(c, t) < clip.rail) out(c, t) = clip.rail;
  return out;
}

}  // namespace

Eigen::VectorXd window_rmse(const HadynetModel& model, const std::vector<HeldOutLog>& logs, int steps) {
  if (steps < 1) throw std::logic_error("window_rmse: steps must be >= 1");
  const OutputMap map = output_map(model);
  const auto ny = static_cast<Eigen::Index>(model.layout.y_names.size());
  Eigen::VectorXd sum_ee = Eigen::VectorXd::Zero(ny);
  Eigen::VectorXd rows = Eigen::VectorXd::Zero(ny);
  for (const auto& log : logs) {
    // Initial states first - 1 - D, every `steps` rows, while a window holds a
    // row before `end` (frame row s >= 1: the first window's x row is 1).
    std::vector<int> starts;
    const int last_start = std::min(log.end - 1, log.frame.steps() - 1 - steps);
    for (int s = std::max(1, log.first - 1 - map.d); s <= last_start; s += steps) starts.push_back(s);
    if (starts.empty()) continue;
    const Eigen::MatrixXd p = predict_windows_from(model, log.frame, log.pb, steps, starts);
    const double dt = log_dt(log.raw->table, log.raw->file);
    std::vector<std::vector<double>> drivers;
    for (const auto& [c, drift] : map.drifts) drivers.push_back(drift_driver(log.raw->table, log.raw->file, drift));
    // The window's prediction of frame row r for channel c, NaN outside it.
    const auto predicted = [&](std::size_t i, Eigen::Index c, int r) {
      const int k = r - starts[i] - 1;
      return k >= 0 && k < steps ? p(c, static_cast<Eigen::Index>(i) * steps + k) : std::nan("");
    };
    for (std::size_t i = 0; i < starts.size(); ++i) {
      for (int t = std::max(log.first, starts[i] + 1); t < log.end && t <= starts[i] + steps + map.d; ++t) {
        Eigen::VectorXd v(ny);
        for (Eigen::Index c = 0; c < ny; ++c) v(c) = predicted(i, c, t - map.delay[static_cast<std::size_t>(c)]);
        for (const auto& [c, curve] : map.curves)
          if (!std::isnan(v(c))) v(c) = curve_reading(curve, v(c));
        for (const auto& x : map.crosstalk) v(x.target) += x.gain * predicted(i, x.source, t);
        for (std::size_t j = 0; j < map.drifts.size(); ++j) {
          const auto& [c, drift] = map.drifts[j];
          if (std::isnan(v(c))) continue;
          const double increment = drift.load ? std::abs(v(c)) * dt : dt;
          v(c) += drift.rate * (drivers[j][static_cast<std::size_t>(t - 1)] + increment);
        }
        for (const auto& [c, clip] : map.clips)
          if (clip.side > 0 ? v(c) > clip.rail : v(c) < clip.rail) v(c) = clip.rail;
        for (Eigen::Index c = 0; c < ny; ++c) {
          if (std::isnan(v(c))) continue;
          const double r = log.measured.y(c, t) - v(c);
          sum_ee(c) += r * r;
          rows(c) += 1;
        }
      }
    }
  }
  if ((rows.array() == 0).any()) throw std::logic_error("window_rmse: a channel has no row in a window");
  return (sum_ee.array() / rows.array()).sqrt().matrix();
}

HeldOutError held_out_error(const HadynetModel& model, const std::vector<HeldOutLog>& logs, HeldOutDetail detail) {
  const OutputMap map = output_map(model);
  HeldOutError e;
  e.channels = model.layout.y_names;
  const auto ny = static_cast<Eigen::Index>(e.channels.size());
  const auto nu = static_cast<Eigen::Index>(model.layout.u_names.size());
  Eigen::VectorXd sum_y = Eigen::VectorXd::Zero(ny), sum_yy = sum_y, sum_ee = sum_y;
  std::vector<Segments> res(static_cast<std::size_t>(ny)), inp(static_cast<std::size_t>(nu));
  for (const auto& log : logs) {
    const Eigen::MatrixXd p = measured_predictions(model, log.frame, log.pb, map, *log.raw, log.measured.steps());
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
    e.residuals.push_back(rc);
    if (detail == HeldOutDetail::kErrorsOnly) continue;
    e.whiteness.push_back(whiteness(rc, kDefaultMaxLag));
    int outside = 0;
    for (const auto& u : inp) outside += cross_correlate(rc, u, kDefaultMaxLag).outside;
    e.inputs_outside.push_back(outside);
  }
  return e;
}

}  // namespace hadynet::trainer::residual
