// CRC-32 of the link's frames (docs/protocol.md): IEEE 802.3 / zlib, the
// reflected polynomial 0xEDB88320, initial value and final xor 0xFFFFFFFF.
// Check value: crc32("123456789") = 0xCBF43926. Table-driven; the 1 KiB table
// is computed at compile time (read-only data: flash on the MCU).
#ifndef HADYNET_FIRMWARE_LINK_CRC32_H_
#define HADYNET_FIRMWARE_LINK_CRC32_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace hadynet::link {

namespace detail {

inline constexpr std::uint32_t kCrc32Polynomial = 0xEDB88320u;  // reflected 0x04C11DB7

constexpr std::array<std::uint32_t, 256> make_crc32_table() noexcept {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? (c >> 1) ^ kCrc32Polynomial : c >> 1;
    table[i] = c;
  }
  return table;
}

inline constexpr std::array<std::uint32_t, 256> kCrc32Table = make_crc32_table();

}  // namespace detail

// Incremental form: state = crc32_begin(); state = crc32_update(state, bytes)...;
// crc = crc32_end(state).
constexpr std::uint32_t crc32_begin() noexcept { return 0xFFFFFFFFu; }

constexpr std::uint32_t crc32_update(std::uint32_t state, std::span<const std::uint8_t> bytes) noexcept {
  for (const std::uint8_t b : bytes) state = detail::kCrc32Table[(state ^ b) & 0xFFu] ^ (state >> 8);
  return state;
}

constexpr std::uint32_t crc32_end(std::uint32_t state) noexcept { return state ^ 0xFFFFFFFFu; }

constexpr std::uint32_t crc32(std::span<const std::uint8_t> bytes) noexcept {
  return crc32_end(crc32_update(crc32_begin(), bytes));
}

}  // namespace hadynet::link

#endif  // HADYNET_FIRMWARE_LINK_CRC32_H_
