// ============================================================================
//  THE FLASH SEAM: erase a sector, program bytes, read bytes, with the
//  sectors described by a table. Backends: the STM32F405 flash interface
//  (boards/stm32f405/flash_controller.h) and SimulatedNorFlash (tests, the
//  fuzzer).
//
//  Contract:
//   * Offsets are bytes from the start of the device (F405: 0x08000000).
//   * erase_sector(i): every byte of sector i reads 0xFF afterwards.
//   * program(offset, data): data must lie inside one sector, offset and size
//     multiples of program_alignment(), and every target byte must read 0xFF
//     (erased); otherwise nothing is written and the error is returned.
//     Programming only clears bits (NOR).
//   * read(offset, out): any range inside the device.
//   * Errors are values (FlashStatus); a failed operation may have changed
//     the target partly (kWriteError, kPowerLoss): the caller treats it as
//     undefined until erased.
//   * Calls block until the operation is done; *_max_ms/us state how long
//     that may take (for DFU's bwPollTimeout).
// ============================================================================
#ifndef HADYNET_FIRMWARE_FLASH_FLASH_DEVICE_H_
#define HADYNET_FIRMWARE_FLASH_FLASH_DEVICE_H_

#include <cstddef>
#include <cstdint>
#include <span>

namespace hadynet::flash {

enum class FlashStatus : std::uint8_t {
  kOk = 0,
  kOutOfRange,     // outside the device, or not a sector index
  kMisaligned,     // program offset/size not multiples of program_alignment()
  kCrossesSector,  // program range spans a sector boundary
  kNotErased,      // program over bytes that are not 0xFF
  kWriteError,     // the controller reported a programming/erase failure
  kPowerLoss,      // (simulation) power was cut during or before this operation
};

struct FlashSector {
  std::uint32_t offset = 0;        // bytes from the device start
  std::uint32_t size = 0;          // bytes
  std::uint32_t erase_max_ms = 0;  // worst-case erase time of this sector, ms
};

class FlashDevice {
 public:
  virtual std::span<const FlashSector> sectors() const noexcept = 0;
  virtual std::uint32_t program_alignment() const noexcept = 0;      // bytes (F405 x32: 4)
  virtual std::uint32_t program_max_us_per_byte() const noexcept = 0;  // worst case, µs
  virtual FlashStatus erase_sector(std::size_t index) noexcept = 0;
  virtual FlashStatus program(std::uint32_t offset, std::span<const std::uint8_t> data) noexcept = 0;
  virtual FlashStatus read(std::uint32_t offset, std::span<std::uint8_t> out) const noexcept = 0;

 protected:
  ~FlashDevice() = default;
};

// Total size: the end of the last sector (sectors are contiguous, ascending).
inline std::uint32_t flash_size(const FlashDevice& device) noexcept {
  const std::span<const FlashSector> s = device.sectors();
  return s.empty() ? 0 : s.back().offset + s.back().size;
}

// The index of the sector holding `offset`, or sectors().size() if none.
inline std::size_t sector_of(std::span<const FlashSector> sectors, std::uint32_t offset) noexcept {
  for (std::size_t i = 0; i < sectors.size(); ++i) {
    if (offset >= sectors[i].offset && offset - sectors[i].offset < sectors[i].size) return i;
  }
  return sectors.size();
}

}  // namespace hadynet::flash

#endif  // HADYNET_FIRMWARE_FLASH_FLASH_DEVICE_H_
