// What the robot's sensors make of the true signals: the switchable effects
// (cross-talk, drift, saturation, sensor delay) and sensor realism (noise, rated
// ranges, ADC/encoder quantisation). Deterministic for a seed.
#pragma once

#include <cstdint>
#include <deque>

#include "host-sim/plant/hand_plant.h"
#include "host-sim/plant/rng.h"

namespace hadynet::plant {

struct SensorNoise {
  double length_mm = 0.005;    // encoder noise (1 sigma)
  double length_lsb_mm = 0.01; // encoder resolution
  double tension_N = 0.2;
  double loadcell_N = 0.02;
  double wrist_rad = 0.001;
  double wrist_lsb_rad = 6.283185307179586 / 16384;  // 14-bit joint module
};

class SensorSimulation {
 public:
  SensorSimulation(const Effects& effects, bool realism, std::uint64_t seed);
  // Maps one true frame to the measured frame. Call once per 0.2 s step.
  Measurement measure(const Measurement& truth);

 private:
  Effects effects_;
  bool realism_;
  SensorNoise noise_;
  Rng rng_;
  std::array<double, kLoadcells> drift_bias_N_{};
  std::deque<std::array<double, kLoadcells>> loadcell_history_;
};

}  // namespace hadynet::plant
