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
#include "firmware/core/model_tensors.h"

namespace hadynet::app {

template <firmware::GeneratedModel M>
class SyntheticFrames {
 public:
  // Frames around the standardisation of `tensors` (the model the frames
  // are for: a model image's self-test must not depend on which model the
  // firmware has compiled in), which must outlive this object.
  explicit SyntheticFrames(std::uint32_t seed,
                           const firmware::ModelTensors<M>& tensors = firmware::kCompiledTensors<M>) noexcept
      : t_model_(&tensors), state_(seed != 0 ? seed : 1) {}

  void next(firmware::SensorFrame<M>& frame) noexcept {
    const firmware::ModelTensors<M>& m = *t_model_;
    for (int i = 0; i < M::kY; ++i) frame.y[i] = m.y_mean[i] + m.y_std[i] * standard_value(i);
    for (int i = 0; i < M::kU; ++i) frame.u_prev[i] = m.u_mean[i] + m.u_std[i] * standard_value(i + M::kY);
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
  const firmware::ModelTensors<M>* t_model_;
  std::uint32_t state_;
  int t_ = 0;
};

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_SYNTHETIC_FRAMES_H_
