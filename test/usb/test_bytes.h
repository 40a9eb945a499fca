// Test data for the USB tests (test/usb, test/dfuse_sim, test/usb_host and
// the flash benchmark): deterministic pseudo-random bytes, and a DFU model
// file assembled byte by byte from the envelope's specification (docs/usb.md),
// independently of the firmware's encoder (firmware/usb/dfu_image.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "firmware/link/crc32.h"

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

// The envelope (magic "HDIM", version 1, reserved 0, payload length, CRC-32
// of the payload; little-endian), then the payload. `crc_xor` and
// `length_override` (0xFFFFFFFF: the true length) make broken files.
inline Bytes model_image_file(const Bytes& payload, std::uint32_t crc_xor = 0,
                              std::uint32_t length_override = 0xFFFFFFFFu) {
  const std::uint32_t crc = link::crc32(payload) ^ crc_xor;
  const std::uint32_t length =
      length_override != 0xFFFFFFFFu ? length_override : static_cast<std::uint32_t>(payload.size());
  Bytes f = {'H', 'D', 'I', 'M', 1, 0, 0, 0};
  for (int k = 0; k < 4; ++k) f.push_back(static_cast<std::uint8_t>(length >> (8 * k)));
  for (int k = 0; k < 4; ++k) f.push_back(static_cast<std::uint8_t>(crc >> (8 * k)));
  f.insert(f.end(), payload.begin(), payload.end());
  return f;
}

}  // namespace hadynet::usb::test_data
