// Q3.12 -> Q0.15 tanh and sigmoid by table lookup and linear interpolation.
// See activation.h for the contract, formats and error bounds.
#include "firmware/core/activation.h"

#include <cstdint>

namespace hadynet::fixed {

namespace {

// tanh(m / 2^(shift + 5)) in Q0.15 for a magnitude 0 <= m <= 32768, where
// the table step 1/32 spans 2^shift input units. shift = 7: m is |x| in
// Q3.12 (tanh). shift = 8: m is |x| in Q3.12 read as |x/2| in Q2.13
// (sigmoid). Result in [0, 32767].
std::int32_t tanh_magnitude(std::int32_t m, int shift) noexcept {
  const std::int32_t index = m >> shift;
  const std::int32_t frac = m & ((std::int32_t{1} << shift) - 1);
  const std::int32_t lo = detail::kTanhQ15Table[index];
  if (frac == 0) {
    return lo;  // also the only path for index 256 (m = 32768, shift 7)
  }
  // index + 1 <= 256 here: m < 32768 when frac != 0 (shift 7), index <= 128
  // (shift 8).
  const std::int32_t hi = detail::kTanhQ15Table[index + 1];
  // (hi - lo) in [0, 1024], frac < 256: the product fits easily in int32 and
  // is non-negative, so the shift rounds half up == half away from zero. The
  // result lies in [lo, hi] and is non-decreasing in m.
  return lo + (((hi - lo) * frac + (std::int32_t{1} << (shift - 1))) >> shift);
}

}  // namespace

std::int16_t tanh_q15(std::int16_t x) noexcept {
  const std::int32_t xi = x;
  const std::int32_t m = xi < 0 ? -xi : xi;  // [0, 32768], no overflow in int32
  const std::int32_t y = tanh_magnitude(m, 7);
  return static_cast<std::int16_t>(xi < 0 ? -y : y);  // y in [0, 32767]
}

std::int16_t sigmoid_q15(std::int16_t x) noexcept {
  const std::int32_t xi = x;
  const std::int32_t m = xi < 0 ? -xi : xi;
  const std::int32_t t_mag = tanh_magnitude(m, 8);  // tanh(|x|/2), [0, 32767]
  const std::int32_t t = xi < 0 ? -t_mag : t_mag;
  // (1 + t) / 2 in Q0.15: (32768 + t) / 2, rounded half up. |t| <= 32746
  // (tanh(4) rounded) gives [11, 32757]; the clamp only guards the
  // representable +1.0 (32768) in case the table ever changes.
  const std::int32_t y = (std::int32_t{32768} + t + 1) >> 1;
  return static_cast<std::int16_t>(y > 32767 ? 32767 : y);  // saturate +1.0
}

}  // namespace hadynet::fixed
