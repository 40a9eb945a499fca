// Little-endian stores and loads of unsigned integers into byte buffers: the
// wire formats the firmware reads and writes by hand (USB descriptors and
// requests, the model image header and trial flags). The caller checks bounds.
#ifndef HADYNET_FIRMWARE_CORE_LITTLE_ENDIAN_H_
#define HADYNET_FIRMWARE_CORE_LITTLE_ENDIAN_H_

#include <cstddef>
#include <cstdint>

namespace hadynet::firmware {

// Stores the low `bytes` bytes of `value` at p[0..bytes), least significant first.
constexpr void store_le(std::uint8_t* p, std::uint64_t value, std::size_t bytes) noexcept {
  for (std::size_t k = 0; k < bytes; ++k) p[k] = static_cast<std::uint8_t>(value >> (8 * k));
}

// Loads `bytes` bytes from p, least significant first.
constexpr std::uint64_t load_le(const std::uint8_t* p, std::size_t bytes) noexcept {
  std::uint64_t value = 0;
  for (std::size_t k = 0; k < bytes; ++k) value |= static_cast<std::uint64_t>(p[k]) << (8 * k);
  return value;
}

constexpr void put_le16(std::uint8_t* p, std::uint16_t v) noexcept { store_le(p, v, 2); }
constexpr void put_le32(std::uint8_t* p, std::uint32_t v) noexcept { store_le(p, v, 4); }
constexpr void put_le64(std::uint8_t* p, std::uint64_t v) noexcept { store_le(p, v, 8); }
constexpr std::uint16_t get_le16(const std::uint8_t* p) noexcept { return static_cast<std::uint16_t>(load_le(p, 2)); }
constexpr std::uint32_t get_le32(const std::uint8_t* p) noexcept { return static_cast<std::uint32_t>(load_le(p, 4)); }
constexpr std::uint64_t get_le64(const std::uint8_t* p) noexcept { return load_le(p, 8); }

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_LITTLE_ENDIAN_H_
