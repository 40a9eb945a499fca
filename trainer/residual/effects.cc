#include "trainer/residual/effects.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace hadynet::trainer::residual {

const std::vector<EffectInfo>& effect_library() {
  static const std::vector<EffectInfo> library = {
      {EffectKind::kSensorDelay, "sensor-delay",
       "y_hat_c(t-d) - y_hat_c(t): the residual a sensor reporting d steps late leaves against the model's "
       "prediction (d = 1..max_delay)",
       "delay d (steps) and the gain of the aligned prediction (1: the whole residual is the delay)",
       "time alignment: train on y_c shifted d steps earlier (the network predicts the true-time signal), "
       "with the winner's group where the same delay tests significant; the delay goes into the sensor model"},
      {EffectKind::kInputDelay, "input-delay",
       "u(t-1-d) - u(t-1), every command channel: commands that act d steps later than the model assumes",
       "delay d (steps)",
       "none (named and reported only): dead time in the commands would change what the stabiliser controls"},
      {EffectKind::kFriction, "friction",
       "sign(u_m(t-1)) and the hysteresis state h_m(t) (sign of the last non-zero command of muscle m): dry "
       "friction acting against the motion of muscle m",
       "the residual offset while muscle m moves in the + direction (target units; minus that in the other)",
       "a hysteresis state as an input: the derived commands sign_u_m and hyst_u_m appended to u"},
      {EffectKind::kDriftLoad, "drift-load",
       "the accumulated load sum_{s<=t} |y_c(s)| dt from the log's start: a bias that grows with the load "
       "the sensor has carried",
       "rate: bias per accumulated load (target units per (target unit s))",
       "a drift/bias state in the sensor model: a per-channel bias integrating |y_c| dt at a re-estimated "
       "rate, subtracted from the measured y_c before the network sees it and added to its prediction"},
      {EffectKind::kDriftTime, "drift-time", "time since the log's start: a bias growing with time",
       "rate: bias per second (target units per s)",
       "a drift/bias state in the sensor model, growing with time at a re-estimated rate"},
      {EffectKind::kSaturation, "saturation",
       "min(y_hat_c, R) - y_hat_c (upper rail R = the largest measured value over the logs; lower: max(y_hat_c, "
       "R) - y_hat_c with the smallest): the part of the prediction a clipped sensor cannot show",
       "the rail R (target units) and the gain (1: fully clipped)",
       "clipping in the sensor model: the prediction of y_c passes min(., R) (max for a lower rail); "
       "fine-tuned on the clipped output"},
      {EffectKind::kCrosstalk, "crosstalk",
       "y_s(t): another channel's measured value (by default of the target's group) leaking into the target",
       "gain: the fraction of y_s the target picks up",
       "removal: train on y_c - k y_s (in y and x); the sensor model adds k times the predicted y_s back"},
      {EffectKind::kAuxChannel, "aux-channel",
       "an aux_* column's value at t: a logged channel the model does not use",
       "gain (target units per aux unit)",
       "use it: the aux channel becomes an observed channel (an input in x, predicted in y)"},
  };
  return library;
}

const EffectInfo& effect_info(EffectKind kind) {
  for (const auto& e : effect_library())
    if (e.kind == kind) return e;
  throw std::logic_error("effect kind without library entry");
}

namespace {

double sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace

Features features(const Hypothesis& h, const ResidualLog& log) {
  const int n = log.size();
  const auto c = static_cast<Eigen::Index>(h.target);
  Features f;
  switch (h.kind) {
    case EffectKind::kSensorDelay: {
      f.z = Eigen::MatrixXd::Zero(n, 1);
      f.first_valid = std::min(h.delay, n);
      for (int j = f.first_valid; j < n; ++j) f.z(j, 0) = log.y_hat(c, j - h.delay) - log.y_hat(c, j);
      break;
    }
    case EffectKind::kInputDelay: {
      const auto nu = log.seq.u.rows();
      f.z = Eigen::MatrixXd::Zero(n, nu);
      f.first_valid = std::clamp(h.delay - 1, 0, n);
      for (int j = f.first_valid; j < n; ++j) {
        const int t = ResidualLog::row(j);
        f.z.row(j) = (log.seq.u.col(t - 1 - h.delay) - log.seq.u.col(t - 1)).transpose();
      }
      break;
    }
    case EffectKind::kFriction: {
      f.z = Eigen::MatrixXd::Zero(n, 2);
      const auto m = static_cast<Eigen::Index>(h.source);
      double state = 0;
      int next_row = 0;  // rows of u folded into `state` so far
      for (int j = 0; j < n; ++j) {
        const int t = ResidualLog::row(j);
        for (; next_row <= t - 1; ++next_row)
          if (log.seq.u(m, next_row) != 0) state = sign(log.seq.u(m, next_row));
        f.z(j, 0) = sign(log.seq.u(m, t - 1));
        f.z(j, 1) = state;
      }
      break;
    }
    case EffectKind::kDriftLoad: {
      f.z = Eigen::MatrixXd::Zero(n, 1);
      double load = 0;
      int next_row = 0;
      for (int j = 0; j < n; ++j) {
        const int t = ResidualLog::row(j);
        for (; next_row <= t; ++next_row) load += std::abs(log.seq.y(c, next_row)) * log.dt_s;
        f.z(j, 0) = load;
      }
      break;
    }
    case EffectKind::kDriftTime: {
      f.z = Eigen::MatrixXd::Zero(n, 1);
      for (int j = 0; j < n; ++j) f.z(j, 0) = ResidualLog::row(j) * log.dt_s;
      break;
    }
    case EffectKind::kSaturation: {
      f.z = Eigen::MatrixXd::Zero(n, 1);
      for (int j = 0; j < n; ++j) {
        const double p = log.y_hat(c, j);
        f.z(j, 0) = (h.side > 0 ? std::min(p, h.rail) : std::max(p, h.rail)) - p;
      }
      break;
    }
    case EffectKind::kCrosstalk: {
      f.z = Eigen::MatrixXd::Zero(n, 1);
      for (int j = 0; j < n; ++j) f.z(j, 0) = log.seq.y(h.source, ResidualLog::row(j));
      break;
    }
    case EffectKind::kAuxChannel: {
      f.z = Eigen::MatrixXd::Zero(n, 1);
      for (int j = 0; j < n; ++j) f.z(j, 0) = log.aux(h.source, ResidualLog::row(j));
      break;
    }
  }
  return f;
}

double main_parameter(const Hypothesis& h, const Eigen::VectorXd& coef) {
  if (coef.size() == 0) return std::numeric_limits<double>::quiet_NaN();
  switch (h.kind) {
    case EffectKind::kFriction:
      return coef.size() >= 2 ? coef(0) + coef(1) : coef(0);
    case EffectKind::kInputDelay:
      return coef.norm();
    default:
      return coef(0);
  }
}

bool plausible(const Hypothesis& h, double parameter) {
  switch (h.kind) {
    case EffectKind::kCrosstalk:
      return parameter > 0 && parameter < 1;
    case EffectKind::kSensorDelay:
    case EffectKind::kSaturation:
      return parameter > 0;
    default:
      return std::isfinite(parameter);
  }
}

std::string describe(const Hypothesis& h, const ResidualData& data, const Eigen::VectorXd& coef) {
  const std::string& target = data.y_names[static_cast<std::size_t>(h.target)];
  const double p = main_parameter(h, coef);
  switch (h.kind) {
    case EffectKind::kSensorDelay:
      return "delay = " + std::to_string(h.delay) + (h.delay == 1 ? " step" : " steps") + " on " + target +
             " (gain" + fmt(" %.2f)", p);
    case EffectKind::kInputDelay:
      return "input delay = " + std::to_string(h.delay) + (h.delay == 1 ? " step" : " steps") + " seen on " +
             target;
    case EffectKind::kFriction:
      return "friction on " + target + " with the motion of " + data.u_names[static_cast<std::size_t>(h.source)] +
             ": " + fmt("%+.3g", p) + " while it moves +";
    case EffectKind::kDriftLoad:
      return "drift on " + target + " with accumulated load: rate " + fmt("%.3g", p) + " per (unit s)";
    case EffectKind::kDriftTime:
      return "drift on " + target + " with time: rate " + fmt("%.3g", p) + " per s";
    case EffectKind::kSaturation:
      return std::string(h.side > 0 ? "upper" : "lower") + " rail of " + target + " at" + fmt(" %.4g", h.rail) +
             " (gain" + fmt(" %.2f)", p);
    case EffectKind::kCrosstalk:
      return "crosstalk " + data.y_names[static_cast<std::size_t>(h.source)] + " -> " + target + ": gain" +
             fmt(" %.3g", p);
    case EffectKind::kAuxChannel:
      return data.aux_names[static_cast<std::size_t>(h.source)] + " explains " + target + ": gain" +
             fmt(" %.3g", p);
  }
  return "";
}

std::vector<Hypothesis> enumerate_hypotheses(const ResidualData& data, const LibraryOptions& options) {
  std::vector<Hypothesis> out;
  const int ny = static_cast<int>(data.y_names.size());
  const int nu = static_cast<int>(data.u_names.size());
  const int na = static_cast<int>(data.aux_names.size());
  for (int c = 0; c < ny; ++c) {
    for (int d = 1; d <= options.max_delay; ++d) out.push_back({EffectKind::kSensorDelay, c, -1, d, 0, 0});
    for (int d = 1; d <= options.max_delay; ++d) out.push_back({EffectKind::kInputDelay, c, -1, d, 0, 0});
    for (int m = 0; m < nu; ++m) out.push_back({EffectKind::kFriction, c, m, 0, 0, 0});
    out.push_back({EffectKind::kDriftLoad, c, -1, 0, 0, 0});
    out.push_back({EffectKind::kDriftTime, c, -1, 0, 0, 0});
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& log : data.logs) {
      lo = std::min(lo, log.seq.y.row(c).minCoeff());
      hi = std::max(hi, log.seq.y.row(c).maxCoeff());
    }
    if (hi > lo) {
      long rows = 0, at_hi = 0, at_lo = 0;
      for (const auto& log : data.logs) {
        const auto y = log.seq.y.row(c).array();
        rows += y.size();
        // "At": within rail_band of the channel's range (a saturated sensor still
        // shows its ADC noise around the rail).
        const double band = options.rail_band * (hi - lo);
        at_hi += (y >= hi - band).count();
        at_lo += (y <= lo + band).count();
      }
      const double need = std::max(5.0, options.min_rail_share * static_cast<double>(rows));
      if (static_cast<double>(at_hi) >= need) out.push_back({EffectKind::kSaturation, c, -1, 0, +1, hi});
      if (static_cast<double>(at_lo) >= need) out.push_back({EffectKind::kSaturation, c, -1, 0, -1, lo});
    }
    const std::string group = channel_group(data.y_names[static_cast<std::size_t>(c)]);
    for (int s = 0; s < ny; ++s) {
      if (s == c) continue;
      if (options.crosstalk_same_group && channel_group(data.y_names[static_cast<std::size_t>(s)]) != group) continue;
      out.push_back({EffectKind::kCrosstalk, c, s, 0, 0, 0});
    }
    for (int a = 0; a < na; ++a) out.push_back({EffectKind::kAuxChannel, c, a, 0, 0, 0});
  }
  return out;
}

}  // namespace hadynet::trainer::residual
