#include "trainer/residual/sensor_readout.h"

#include <algorithm>
#include <stdexcept>

namespace hadynet::trainer::residual {

SensorReadout::SensorReadout(const std::vector<std::string>& y_names, const SensorModel& sensor, const LogInput& log) {
  const auto row = [&](const std::string& name) {
    const auto it = std::find(y_names.begin(), y_names.end(), name);
    if (it == y_names.end()) throw std::logic_error("--fix: sensor model channel " + name + " not in the model");
    return static_cast<Eigen::Index>(it - y_names.begin());
  };
  delay_.assign(y_names.size(), 0);
  max_delay_ = sensor.max_delay();
  for (const SensorDelay& x : sensor.delays) delay_[static_cast<std::size_t>(row(x.channel))] = x.steps;
  for (const SensorCurve& curve : sensor.curves) curves_.emplace_back(row(curve.channel), curve);
  for (const SensorCrosstalk& x : sensor.crosstalk) crosstalk_.push_back({row(x.target), row(x.source), x.gain});
  dt_ = log_dt(log.table, log.file);
  for (const SensorDrift& drift : sensor.drifts)
    drifts_.push_back({row(drift.channel), drift.load, drift.rate, drift_driver(log.table, log.file, drift)});
  for (const OutputClip& clip : sensor.clips) clips_.emplace_back(row(clip.channel), clip);
}

}  // namespace hadynet::trainer::residual
