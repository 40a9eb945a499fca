// A fixed run of the runtime over synthetic frames and a checksum of every
// result, bit for bit: the q15 figure must be the same on the host
// (reference kernels) and on the MCU (optimised kernels), which the QEMU test
// checks (test/boards/). The f32 build's transcendental functions come from
// each platform's C library, so its checksum is reported but not compared.
#ifndef HADYNET_FIRMWARE_APP_RUNTIME_CHECKSUM_H_
#define HADYNET_FIRMWARE_APP_RUNTIME_CHECKSUM_H_

#include <bit>
#include <cstdint>

#include "firmware/app/synthetic_frames.h"
#include "firmware/core/hadynet_runtime.h"

namespace hadynet::app {

inline constexpr std::uint32_t kChecksumSeed = 0x1D2C3B4Au;
inline constexpr int kChecksumDetectFrames = 10;   // detect mode: the history fills, d appears
inline constexpr int kChecksumControlFrames = 4;  // then control mode: the stabiliser plans

class Fnv1a64 {
 public:
  void add(std::uint32_t word) noexcept {
    for (int i = 0; i < 4; ++i) {
      hash_ ^= (word >> (8 * i)) & 0xFFu;
      hash_ *= 0x100000001B3ull;
    }
  }
  void add(float v) noexcept { add(std::bit_cast<std::uint32_t>(v)); }
  void add(bool v) noexcept { add(static_cast<std::uint32_t>(v ? 1 : 0)); }
  std::uint64_t value() const noexcept { return hash_; }

 private:
  std::uint64_t hash_ = 0xCBF29CE484222325ull;
};

template <firmware::GeneratedModel M>
void add_result(Fnv1a64& h, const firmware::StepResult<M>& r) noexcept {
  h.add(r.prediction_valid);
  for (const float v : r.prediction) h.add(v);
  h.add(r.distance_valid);
  h.add(r.d);
  h.add(r.contact);
  h.add(r.command_valid);
  for (const float v : r.command) h.add(v);
}

// Runs a freshly constructed runtime through the fixed sequence (detect
// mode, then control mode with the default settings; frames around the
// standardisation of the model it runs) and returns the checksum of all
// results: a function of the runtime's model alone, so a model image's
// self-test checksum is reproduced by any firmware of its shape.
template <firmware::GeneratedModel M>
std::uint64_t runtime_checksum(firmware::HadynetRuntime<M>& runtime) noexcept {
  SyntheticFrames<M> frames(kChecksumSeed, runtime.tensors());
  Fnv1a64 h;
  firmware::SensorFrame<M> frame;
  runtime.set_mode(firmware::Mode::kDetect);
  for (int k = 0; k < kChecksumDetectFrames + kChecksumControlFrames; ++k) {
    if (k == kChecksumDetectFrames) runtime.set_mode(firmware::Mode::kControl);
    frames.next(frame);
    add_result(h, runtime.step(frame));
  }
  return h.value();
}

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_RUNTIME_CHECKSUM_H_
