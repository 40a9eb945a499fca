// Deterministic sensor frames for the benchmark and the runtime checksum
// (the same sequence on the host and the MCU): every channel is its
// training mean plus a slowly turning pattern and pseudo-random noise, in
// standard deviations, converted to physical units with one IEEE multiply
// and one add each (-ffp-contract=off), so host and MCU build bit-identical
// frames. Not a plant: the values only need to be plausible.
#ifndef HADYNET_FIRMWARE_APP_SYNTHETIC_FRAMES_H_
#define HADYNET_FIRMWARE_APP_SYNTHETIC_FRAMES_H_

#include <cstdint>

#include "firmware/core/hadynet_runtime.h"

namespace hadynet::app {

template <firmware::GeneratedModel M>
class SyntheticFrames {
 public:
  explicit SyntheticFrames(std::uint32_t seed) noexcept : state_(seed != 0 ? seed : 1) {}

  void next(firmware::SensorFrame<M>& frame) noexcept {
    for (int i = 0; i < M::kY; ++i) frame.y[i] = M::kYMean[i] + M::kYStd[i] * standard_value(i);
    for (int i = 0; i < M::kU; ++i) frame.u_prev[i] = M::kUMean[i] + M::kUStd[i] * standard_value(i + M::kY);
    ++t_;
  }

 private:
  // Pattern in [-0.5, 0.5] (a triangle wave, period 16 frames, phase per
  // channel) plus noise in [-0.25, 0.25], in standard deviations.
  float standard_value(int channel) noexcept {
    const int phase = (t_ + 3 * channel) % 16;
    const int tri = phase < 8 ? phase - 4 : 12 - phase;  // -4 .. 4
    const int noise = static_cast<int>(next_random() % 501u) - 250;
    return static_cast<float>(tri) / 8.0f + static_cast<float>(noise) / 1000.0f;
  }
  std::uint32_t next_random() noexcept {  // xorshift32
    state_ ^= state_ << 13;
    state_ ^= state_ >> 17;
    state_ ^= state_ << 5;
    return state_;
  }
  std::uint32_t state_;
  int t_ = 0;
};

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_SYNTHETIC_FRAMES_H_
