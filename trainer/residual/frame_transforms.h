// The data side of `hadynet residual --fix` (docs/residual.md): logs moved
// into the frame an augmented model is trained and evaluated in. Each
// function returns new tables and leaves the input untouched; columns are
// found by name, and a missing one is an error naming the file.
#pragma once

#include <string>
#include <vector>

#include "trainer/residual/residuals.h"

namespace hadynet::trainer::residual {

// The control period of a log: metadata dt_s (s), 1 if absent. Throws
// std::runtime_error naming the file if it is not a positive number.
double log_dt(const LogInput& log);

// Time alignment of a sensor delay: the `channels` columns shifted `delay`
// rows earlier, y'_c(s) = y_c(s + delay); the last `delay` rows are dropped.
std::vector<LogInput> time_aligned(const std::vector<LogInput>& logs, const std::vector<std::string>& channels,
                                   int delay);

// Cross-talk removal: in every row, target -= gain * source.
std::vector<LogInput> crosstalk_removed(const std::vector<LogInput>& logs, const std::string& target,
                                        const std::string& source, double gain);

// A sensor drift as a bias state b_c(t) = rate * D_c(t), where D_c is
//   load: sum_{s <= t} |y_c(s)| dt   (the load the sensor has carried since the log's start)
//   time: t dt                         (time since the log's start)
// with dt the log's metadata dt_s (1 if absent).
struct DriftState {
  std::string channel;
  bool load = true;  // false: time
  double rate = 0;   // channel units per (unit s), or per s
};

// D_c of every row of one log (see DriftState), from the measured column.
std::vector<double> drift_driver(const LogInput& log, const DriftState& drift);

// Drift removal: y'_c(t) = y_c(t) - rate * D_c(t) for every drift, D_c from
// the measured (drifting) column.
std::vector<LogInput> drift_removed(const std::vector<LogInput>& logs, const std::vector<DriftState>& drifts);

}  // namespace hadynet::trainer::residual
