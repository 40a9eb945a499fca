// The limits the model-file reader enforces (docs/input-limits.md):
// every model it accepts can be loaded in bounded memory and computed on in
// float32 without overflow, so no command meets an absurd model after
// loading it. Each limit is far above any model this project trains (the
// hand's: x 37, u 8, y 27, pb 8, hidden 128, 50 states, N_train 10).
#pragma once

#include <cstdint>

namespace hadynet::trainer {

struct ModelLimits {
  static constexpr std::int64_t kMaxChannels = 4096;    // dims.y, dims.u (a log's columns)
  static constexpr std::int64_t kMaxX = 2 * kMaxChannels;  // y plus the delta channels
  static constexpr std::int64_t kMaxPb = 256;
  static constexpr std::int64_t kMaxHidden = 1024;
  static constexpr std::int64_t kMaxStates = 100000;
  static constexpr std::int64_t kMaxTrainSteps = 4096;   // N_train: 13 min at 0.2 s
  static constexpr std::int64_t kMaxDelaySteps = 4096;   // a sensor delay, rows
  static constexpr std::int64_t kMaxCurveKnots = 256;    // knots of a calibration curve
  // Largest magnitude of any stored number (weights, means, statistics,
  // sensor-model parameters): beyond it float32 arithmetic overflows.
  static constexpr double kMaxMagnitude = 1e30;
  // A standardisation std below this divides float32 signals into overflow
  // (a denormal std); above it no measured signal lies.
  static constexpr double kMinStd = 1e-12;
};

}  // namespace hadynet::trainer
