#include "host-sim/plant/sensor_simulation.h"

#include <algorithm>
#include <cmath>

#include "host-sim/plant/hand_geometry.h"

namespace hadynet::plant {
namespace g = geometry;

namespace {
// Rounds to a multiple of `lsb`. Decimal resolutions (0.01 mm) divide by the
// whole number of steps per unit, so that the result prints as e.g. 250.51.
double quantise(double value, double lsb) {
  const double per_unit = 1.0 / lsb;
  if (std::abs(per_unit - std::round(per_unit)) < 1e-9) return std::round(value * per_unit) / std::round(per_unit);
  return std::round(value / lsb) * lsb;
}
// Fingertip loadcell i (0 thumb .. 4 little) picks up its neighbour's force.
constexpr int kCrosstalkSource[5] = {1, 2, 3, 4, 3};
// The tension leak: palm loadcell fc6 picks up tendon 5's tension.
constexpr int kLeakLoadcell = 6, kLeakTendon = 5;
}  // namespace

SensorSimulation::SensorSimulation(const Effects& effects, bool realism, std::uint64_t seed)
    : effects_(effects), realism_(realism), rng_(seed) {}

Measurement SensorSimulation::measure(const Measurement& truth) {
  Measurement out = truth;
  auto& fc = out.loadcell_N;
  if (effects_.loadcell_curve_exponent != 1.0)
    for (auto& v : fc) v = g::kLoadcellRange_N * std::pow(std::max(v, 0.0) / g::kLoadcellRange_N, effects_.loadcell_curve_exponent);
  if (effects_.loadcell_crosstalk > 0)
    for (int i = 0; i < 5; ++i) fc[i] += effects_.loadcell_crosstalk * truth.loadcell_N[kCrosstalkSource[i]];
  if (effects_.tension_leak > 0) fc[kLeakLoadcell] += effects_.tension_leak * truth.tension_N[kLeakTendon];
  if (effects_.loadcell_drift_per_Ns > 0 || effects_.loadcell_drift_walk_N > 0) {
    for (int i = 0; i < kLoadcells; ++i) {
      drift_bias_N_[i] += effects_.loadcell_drift_per_Ns * truth.loadcell_N[i] * g::kControlStep_s +
                          effects_.loadcell_drift_walk_N * rng_.normal();
      fc[i] += drift_bias_N_[i];
    }
  }
  if (effects_.loadcell_rail_N > 0)
    for (auto& v : fc) v = std::min(v, effects_.loadcell_rail_N);

  if (realism_) {
    const double tension_lsb = g::kRatedTension_N / (1 << g::kAdcBits);
    const double loadcell_lsb = g::kLoadcellRange_N / (1 << g::kAdcBits);
    for (auto& v : out.muscle_length_mm) v = quantise(v + noise_.length_mm * rng_.normal(), noise_.length_lsb_mm);
    for (auto& v : out.tension_N)
      v = quantise(std::clamp(v + noise_.tension_N * rng_.normal(), 0.0, g::kRatedTension_N), tension_lsb);
    for (auto& v : fc)
      v = quantise(std::clamp(v + noise_.loadcell_N * rng_.normal(), 0.0, g::kLoadcellRange_N), loadcell_lsb);
    for (auto& v : out.wrist_rad) v = quantise(v + noise_.wrist_rad * rng_.normal(), noise_.wrist_lsb_rad);
  }

  if (effects_.loadcell_delay_steps > 0) {
    // Reported values are those measured this many steps ago; until the
    // pipeline has filled, the first measurement is repeated.
    loadcell_history_.push_back(fc);
    while (static_cast<int>(loadcell_history_.size()) > effects_.loadcell_delay_steps + 1)
      loadcell_history_.pop_front();
    fc = loadcell_history_.front();
  }
  return out;
}

}  // namespace hadynet::plant
