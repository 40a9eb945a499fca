#include "trainer/residual/held_out.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "trainer/residual/sensor_readout.h"

namespace hadynet::trainer::residual {

namespace {

// Physical predictions of the measured rows of one log (y x T_raw, NaN where
// there is none): see the header for the frame and the D + 1 steps. Row t
// reads every channel from the window that starts at frame row t - D - 1,
// whose step k predicts frame row t - D + k.
Eigen::MatrixXd measured_predictions(const HadynetModel& model, const HeldOutLog& log) {
  const SensorReadout readout(model.layout.y_names, model.sensor, *log.raw);
  const int d = readout.max_delay();
  const int rows_raw = log.measured.steps();
  const Eigen::MatrixXd p = predict_windows(model, log.frame, log.pb, d + 1);
  const Eigen::Index B = p.cols() / (d + 1);
  Eigen::MatrixXd out = Eigen::MatrixXd::Constant(p.rows(), rows_raw, std::numeric_limits<double>::quiet_NaN());
  for (int t = d + 2; t < rows_raw; ++t) {
    const Eigen::Index b = t - d - 2;  // window starting at frame row t - d - 1
    if (b >= B) break;
    const auto frame = [&](Eigen::Index c, int r) { return p(c, (r - t + d) * B + b); };
    out.col(t) = readout.row(frame, t);
  }
  return out;
}

}  // namespace

Eigen::VectorXd window_rmse(const HadynetModel& model, const std::vector<HeldOutLog>& logs, int steps) {
  if (steps < 1) throw std::logic_error("window_rmse: steps must be >= 1");
  const auto ny = static_cast<Eigen::Index>(model.layout.y_names.size());
  Eigen::VectorXd sum_ee = Eigen::VectorXd::Zero(ny);
  Eigen::VectorXd rows = Eigen::VectorXd::Zero(ny);
  for (const auto& log : logs) {
    const SensorReadout readout(model.layout.y_names, model.sensor, *log.raw);
    const int d = readout.max_delay();
    // Initial states first - 1 - D, every `steps` rows, while a window holds a
    // row before `end` (frame row s >= 1: the first window's x row is 1).
    std::vector<int> starts;
    const int last_start = std::min(log.end - 1, log.frame.steps() - 1 - steps);
    for (int s = std::max(1, log.first - 1 - d); s <= last_start; s += steps) starts.push_back(s);
    if (starts.empty()) continue;
    const Eigen::MatrixXd p = predict_windows_from(model, log.frame, log.pb, steps, starts);
    // The prediction of frame row r by the window that holds it (the windows
    // are consecutive), NaN outside them.
    const auto frame = [&](Eigen::Index c, int r) {
      const int from_first = r - starts.front() - 1;
      const int i = from_first / steps;
      if (from_first < 0 || i >= static_cast<int>(starts.size())) return std::nan("");
      return p(c, static_cast<Eigen::Index>(i) * steps + from_first % steps);
    };
    for (int t = std::max(log.first, starts.front() + 1); t < log.end && t <= starts.back() + steps + d; ++t) {
      const Eigen::VectorXd v = readout.row(frame, t);
      for (Eigen::Index c = 0; c < ny; ++c) {
        if (std::isnan(v(c))) continue;
        const double r = log.measured.y(c, t) - v(c);
        sum_ee(c) += r * r;
        rows(c) += 1;
      }
    }
  }
  if ((rows.array() == 0).any()) throw std::logic_error("window_rmse: a channel has no row in a window");
  return (sum_ee.array() / rows.array()).sqrt().matrix();
}

HeldOutError held_out_error(const HadynetModel& model, const std::vector<HeldOutLog>& logs, HeldOutDetail detail) {
  HeldOutError e;
  e.channels = model.layout.y_names;
  const auto ny = static_cast<Eigen::Index>(e.channels.size());
  const auto nu = static_cast<Eigen::Index>(model.layout.u_names.size());
  Eigen::VectorXd sum_y = Eigen::VectorXd::Zero(ny), sum_yy = sum_y, sum_ee = sum_y;
  std::vector<Segments> res(static_cast<std::size_t>(ny)), inp(static_cast<std::size_t>(nu));
  for (const auto& log : logs) {
    const Eigen::MatrixXd p = measured_predictions(model, log);
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
