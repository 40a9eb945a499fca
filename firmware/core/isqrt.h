// Integer square root (reference kernel; freestanding, no float).
#ifndef HADYNET_FIRMWARE_CORE_ISQRT_H_
#define HADYNET_FIRMWARE_CORE_ISQRT_H_

#include <cstdint>

namespace hadynet::fixed {

// floor(sqrt(x)) for every uint64 x, exactly (bit-by-bit method: 32
// iterations of shifts, adds and compares; no division, no float).
[[nodiscard]] constexpr std::uint32_t isqrt_u64(std::uint64_t x) noexcept {
  std::uint64_t root = 0;
  std::uint64_t bit = std::uint64_t{1} << 62;  // highest power of four <= 2^63
  while (bit > x) {
    bit >>= 2;
  }
  while (bit != 0) {
    if (x >= root + bit) {
      x -= root + bit;
      root = (root >> 1) + bit;
    } else {
      root >>= 1;
    }
    bit >>= 2;
  }
  return static_cast<std::uint32_t>(root);
}

// sqrt(x) rounded to nearest (ties cannot occur for integers): floor root r,
// plus one if x - r^2 > r (i.e. x >= (r + 1/2)^2 = r^2 + r + 1/4), saturated
// at UINT32_MAX (only x > (2^32 - 1/2)^2 rounds above it).
[[nodiscard]] constexpr std::uint32_t isqrt_round_u64(std::uint64_t x) noexcept {
  const std::uint64_t r = isqrt_u64(x);
  if (r == 0xffffffffu) {
    return 0xffffffffu;
  }
  return static_cast<std::uint32_t>(x - r * r > r ? r + 1 : r);
}

}  // namespace hadynet::fixed

#endif  // HADYNET_FIRMWARE_CORE_ISQRT_H_
