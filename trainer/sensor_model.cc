#include "trainer/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "datalog/log_reader.h"

namespace hadynet::trainer {

namespace {

std::size_t column(const datalog::LogTable& table, const std::string& file, const std::string& name) {
  const auto c = table.column_index(name);
  if (!c) throw std::runtime_error(file + ": no column '" + name + "' (the model's sensor model needs it)");
  return *c;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

void SensorModel::check(const std::vector<std::string>& y_names) const {
  const auto need_channel = [&](const std::string& name, const std::string& what) {
    if (std::find(y_names.begin(), y_names.end(), name) == y_names.end())
      throw std::invalid_argument("sensor model: " + what + " on '" + name + "', not a y channel");
  };
  for (std::size_t i = 0; i < delays.size(); ++i) {
    need_channel(delays[i].channel, "delay");
    if (delays[i].steps < 1) throw std::invalid_argument("sensor model: delay of " + delays[i].channel + " < 1 step");
    for (std::size_t j = 0; j < i; ++j)
      if (delays[j].channel == delays[i].channel)
        throw std::invalid_argument("sensor model: two delays on " + delays[i].channel);
  }
  for (const auto& x : crosstalk) {
    need_channel(x.target, "cross-talk");
    need_channel(x.source, "cross-talk");
    if (x.target == x.source || !std::isfinite(x.gain))
      throw std::invalid_argument("sensor model: cross-talk " + x.source + " -> " + x.target + " is invalid");
  }
  if (!drifts.empty() && !(period_s > 0 && std::isfinite(period_s)))
    throw std::invalid_argument("sensor model: drifts need a positive period_s");
  for (const auto& d : drifts) {
    need_channel(d.channel, "drift");
    if (!std::isfinite(d.rate)) throw std::invalid_argument("sensor model: drift rate on " + d.channel + " not finite");
    if (d.load && d.rate < 0)  // SensorDrift: the level's driver would grow exponentially
      throw std::invalid_argument("sensor model: load drift rate on " + d.channel + " is negative");
  }
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const SensorCurve& c = curves[i];
    need_channel(c.channel, "curve");
    for (std::size_t j = 0; j < i; ++j)
      if (curves[j].channel == c.channel) throw std::invalid_argument("sensor model: two curves on " + c.channel);
    if (c.level.size() < 2 || c.level.size() != c.reading.size())
      throw std::invalid_argument("sensor model: the curve of " + c.channel + " needs >= 2 knots, as many readings");
    for (std::size_t k = 0; k < c.level.size(); ++k) {
      if (!std::isfinite(c.level[k]) || !std::isfinite(c.reading[k]))
        throw std::invalid_argument("sensor model: the curve of " + c.channel + " has a knot that is not finite");
      if (k > 0 && !(c.level[k] > c.level[k - 1] && c.reading[k] > c.reading[k - 1]))
        throw std::invalid_argument("sensor model: the curve of " + c.channel + " is not strictly increasing");
    }
  }
  for (const auto& c : clips) {
    need_channel(c.channel, "output clip");
    if (c.side != 1 && c.side != -1) throw std::invalid_argument("sensor model: output clip side must be +1 or -1");
    if (!std::isfinite(c.rail)) throw std::invalid_argument("sensor model: output clip rail not finite");
  }
}

std::vector<std::string> SensorModel::describe() const {
  std::vector<std::string> out;
  for (const auto& d : delays) out.push_back(d.channel + " reported " + std::to_string(d.steps) + " steps late");
  for (const auto& x : crosstalk) out.push_back(x.target + " += " + num(x.gain) + " * " + x.source);
  for (const auto& d : drifts)
    out.push_back(d.channel + " += " + num(d.rate) + (d.load ? " * sum |" + d.channel + " level| dt" : std::string(" * t")));
  for (const auto& c : curves) {
    std::string knots;
    for (std::size_t k = 0; k < c.level.size(); ++k)
      knots += (k ? ", " : "") + num(c.level[k]) + " -> " + num(c.reading[k]);
    out.push_back(c.channel + " reads g(" + c.channel + "), g through " + knots);
  }
  for (const auto& c : clips) out.push_back(c.channel + (c.side > 0 ? " <= " : " >= ") + num(c.rail));
  return out;
}

const SensorCurve* SensorModel::curve_of(const std::string& channel) const {
  for (const auto& c : curves)
    if (c.channel == channel) return &c;
  return nullptr;
}

namespace {

// The piecewise-linear map through (from[k], to[k]), continued along the end
// segments; `from` strictly increasing, >= 2 knots.
double piecewise_linear(const std::vector<double>& from, const std::vector<double>& to, double v) {
  const std::size_t n = from.size();
  std::size_t k = 1;  // segment [k - 1, k]
  while (k + 1 < n && v > from[k]) ++k;
  return to[k - 1] + (v - from[k - 1]) * (to[k] - to[k - 1]) / (from[k] - from[k - 1]);
}

}  // namespace

double curve_reading(const SensorCurve& c, double level) { return piecewise_linear(c.level, c.reading, level); }
double curve_level(const SensorCurve& c, double reading) { return piecewise_linear(c.reading, c.level, reading); }

double curve_slope(const SensorCurve& c, double level) {
  const std::size_t n = c.level.size();
  std::size_t k = 1;  // segment [k - 1, k]; a knot belongs to the segment above it
  while (k + 1 < n && level >= c.level[k]) ++k;
  return (c.reading[k] - c.reading[k - 1]) / (c.level[k] - c.level[k - 1]);
}

int SensorModel::max_delay() const {
  int d = 0;
  for (const auto& x : delays) d = std::max(d, x.steps);
  return d;
}

int SensorModel::delay_of(const std::string& channel) const {
  for (const auto& x : delays)
    if (x.channel == channel) return x.steps;
  return 0;
}

double log_dt(const datalog::LogTable& table, const std::string& file) {
  if (!table.metadata.get("dt_s")) return 1.0;
  return datalog::log_dt_s(table, file);
}

std::vector<double> drift_driver(const datalog::LogTable& table, const std::string& file, const SensorDrift& drift) {
  const std::size_t c = column(table, file, drift.channel);
  const double dt = log_dt(table, file);
  std::vector<double> d(table.rows());
  if (!drift.load) {
    for (std::size_t r = 0; r < d.size(); ++r) d[r] = static_cast<double>(r) * dt;
    return d;
  }
  double level = 0;  // the accumulated level (SensorDrift: the reading less its bias)
  for (std::size_t r = 0; r < d.size(); ++r) {
    level = (level + std::abs(table.at(r, c)) * dt) / (1 + drift.rate * dt);
    d[r] = level;
  }
  return d;
}

datalog::LogTable time_aligned(const datalog::LogTable& t, const std::string& file,
                               const std::vector<SensorDelay>& delays) {
  if (delays.empty()) return t;
  const std::size_t T = t.rows(), cols = t.columns.size();
  std::vector<std::size_t> shift(cols, 0);
  std::size_t d = 0;
  for (const auto& x : delays) {
    if (x.steps < 1) throw std::invalid_argument("time alignment: delay < 1 step");
    shift[column(t, file, x.channel)] = static_cast<std::size_t>(x.steps);
    d = std::max(d, static_cast<std::size_t>(x.steps));
  }
  if (T <= d) throw std::runtime_error(file + ": fewer rows than the sensor delay");
  datalog::LogTable aligned;
  aligned.metadata = t.metadata;
  aligned.columns = t.columns;
  aligned.values.reserve((T - d) * cols);
  for (std::size_t r = 0; r + d < T; ++r)
    for (std::size_t c = 0; c < cols; ++c) aligned.values.push_back(t.at(r + shift[c], c));
  return aligned;
}

datalog::LogTable crosstalk_removed(const datalog::LogTable& table, const std::string& file,
                                    const std::vector<SensorCrosstalk>& crosstalk,
                                    const std::vector<SensorCurve>& curves) {
  datalog::LogTable out = table;
  for (const auto& x : crosstalk) {
    // Every pair removes its source's measured value (not a source already
    // corrected), through the source's curve if it has one: the sensor
    // model adds the network's sources.
    const std::size_t c = column(out, file, x.target), s = column(table, file, x.source);
    const auto curve = std::find_if(curves.begin(), curves.end(), [&](const SensorCurve& g) { return g.channel == x.source; });
    for (std::size_t r = 0; r < out.rows(); ++r)
      out.at(r, c) -= x.gain * (curve == curves.end() ? table.at(r, s) : curve_level(*curve, table.at(r, s)));
  }
  return out;
}

datalog::LogTable drift_removed(const datalog::LogTable& table, const std::string& file,
                                const std::vector<SensorDrift>& drifts) {
  datalog::LogTable out = table;
  for (const auto& drift : drifts) {
    const std::vector<double> d = drift_driver(table, file, drift);  // from the measured column
    const std::size_t c = column(out, file, drift.channel);
    for (std::size_t r = 0; r < d.size(); ++r) out.at(r, c) -= drift.rate * d[r];
  }
  return out;
}

datalog::LogTable curves_inverted(const datalog::LogTable& table, const std::string& file,
                                  const std::vector<SensorCurve>& curves) {
  datalog::LogTable out = table;
  for (const auto& curve : curves) {
    const std::size_t c = column(out, file, curve.channel);
    for (std::size_t r = 0; r < out.rows(); ++r) out.at(r, c) = curve_level(curve, out.at(r, c));
  }
  return out;
}

datalog::LogTable to_model_frame(const SensorModel& sensor, const datalog::LogTable& table, const std::string& file) {
  if (sensor.frame_is_measured()) return table;
  const datalog::LogTable without_bias =
      crosstalk_removed(drift_removed(table, file, sensor.drifts), file, sensor.crosstalk, sensor.curves);
  return time_aligned(curves_inverted(without_bias, file, sensor.curves), file, sensor.delays);
}

namespace {

// The measured channel is the frame's plus a term that changes every row: a
// cross-talk target or a drifting channel.
bool frame_offsets(const SensorModel& sensor, const std::string& channel) {
  return std::any_of(sensor.crosstalk.begin(), sensor.crosstalk.end(),
                     [&](const SensorCrosstalk& x) { return x.target == channel; }) ||
         std::any_of(sensor.drifts.begin(), sensor.drifts.end(),
                     [&](const SensorDrift& x) { return x.channel == channel; });
}

}  // namespace

std::optional<double> frame_rail(const SensorModel& sensor, const OutputClip& clip) {
  if (frame_offsets(sensor, clip.channel)) return std::nullopt;
  if (const SensorCurve* curve = sensor.curve_of(clip.channel)) return curve_level(*curve, clip.rail);
  return clip.rail;
}

bool frame_transforms(const SensorModel& sensor, const std::string& channel) {
  return sensor.curve_of(channel) != nullptr || frame_offsets(sensor, channel);
}

}  // namespace hadynet::trainer
