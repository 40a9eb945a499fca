// Test data for the USB tests (test/usb, test/dfuse_sim, test/usb_host and
// the flash benchmark): deterministic pseudo-random bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hadynet::usb::test_data {

using Bytes = std::vector<std::uint8_t>;

// The top bytes of a linear congruential generator started at `seed`: the
// same bytes for the same (n, seed) on every platform.
inline Bytes pseudo_random(std::size_t n, std::uint32_t seed) {
  Bytes b(n);
  std::uint32_t x = seed;
  for (auto& v : b) {
    x = x * 1664525u + 1013904223u;
    v = static_cast<std::uint8_t>(x >> 24);
  }
  return b;
}

}  // namespace hadynet::usb::test_data
