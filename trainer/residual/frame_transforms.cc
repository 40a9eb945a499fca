#include "trainer/residual/frame_transforms.h"

#include <cmath>
#include <stdexcept>

namespace hadynet::trainer::residual {

namespace {

std::size_t column(const LogInput& in, const std::string& name) {
  const auto c = in.table.column_index(name);
  if (!c) throw std::runtime_error(in.file + ": no column '" + name + "'");
  return *c;
}

}  // namespace

double log_dt(const LogInput& in) {
  const auto dt = in.table.metadata.get("dt_s");
  if (!dt) return 1.0;
  try {
    std::size_t used = 0;
    const double v = std::stod(*dt, &used);
    if (used == dt->size() && std::isfinite(v) && v > 0) return v;
  } catch (const std::exception&) {
  }
  throw std::runtime_error(in.file + ": metadata dt_s '" + *dt + "' is not a positive number");
}

std::vector<LogInput> time_aligned(const std::vector<LogInput>& logs, const std::vector<std::string>& channels,
                                   int delay) {
  if (delay < 0) throw std::invalid_argument("time alignment: negative delay");
  std::vector<LogInput> out;
  for (const auto& in : logs) {
    const auto& t = in.table;
    const std::size_t T = t.rows(), cols = t.columns.size(), d = static_cast<std::size_t>(delay);
    if (T <= d) throw std::runtime_error(in.file + ": fewer rows than the delay");
    std::vector<bool> shifted(cols, false);
    for (const auto& name : channels) shifted[column(in, name)] = true;
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

std::vector<LogInput> crosstalk_removed(const std::vector<LogInput>& logs, const std::string& target,
                                        const std::string& source, double gain) {
  std::vector<LogInput> out = logs;
  for (auto& in : out) {
    const std::size_t c = column(in, target), s = column(in, source);
    for (std::size_t r = 0; r < in.table.rows(); ++r) in.table.at(r, c) -= gain * in.table.at(r, s);
  }
  return out;
}

std::vector<double> drift_driver(const LogInput& log, const DriftState& drift) {
  const std::size_t c = column(log, drift.channel);
  const double dt = log_dt(log);
  std::vector<double> d(log.table.rows());
  double load = 0;
  for (std::size_t r = 0; r < d.size(); ++r) {
    load += std::abs(log.table.at(r, c)) * dt;
    d[r] = drift.load ? load : static_cast<double>(r) * dt;
  }
  return d;
}

std::vector<LogInput> drift_removed(const std::vector<LogInput>& logs, const std::vector<DriftState>& drifts) {
  std::vector<LogInput> out = logs;
  for (std::size_t i = 0; i < logs.size(); ++i)
    for (const DriftState& drift : drifts) {
      // The driver comes from the measured column, before any removal.
      const std::vector<double> d = drift_driver(logs[i], drift);
      const std::size_t c = column(out[i], drift.channel);
      for (std::size_t r = 0; r < d.size(); ++r) out[i].table.at(r, c) -= drift.rate * d[r];
    }
  return out;
}

}  // namespace hadynet::trainer::residual
