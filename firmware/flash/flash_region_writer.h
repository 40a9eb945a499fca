// Writes a byte stream into a flash region through the flash seam:
// sequential appends from a start offset, sectors erased lazily (the first
// time a write reaches them, so a refused download never erases anything),
// programs split at sector boundaries and kept to the device's program
// alignment (a partial unit is held until more bytes come or finish() pads
// it with 0xFF, which leaves erased cells as they are). Also single aligned
// writes behind the stream (a header written last). No heap.
#ifndef HADYNET_FIRMWARE_FLASH_FLASH_REGION_WRITER_H_
#define HADYNET_FIRMWARE_FLASH_FLASH_REGION_WRITER_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/flash/flash_device.h"

namespace hadynet::flash {

struct FlashRegion {
  std::uint32_t offset = 0;  // device offset of the first byte
  std::uint32_t size = 0;    // bytes
};

// True if the region is non-empty, inside the device and starts and ends on
// sector boundaries (erasing it touches nothing else).
bool region_is_sector_aligned(std::span<const FlashSector> sectors, const FlashRegion& region) noexcept;

struct WriteResult {
  FlashStatus status = FlashStatus::kOk;
  bool during_erase = false;  // the failing operation was an erase
  constexpr bool ok() const noexcept { return status == FlashStatus::kOk; }
};

class FlashRegionWriter {
 public:
  static constexpr std::size_t kMaxAlignment = 16;  // bytes; larger program units are refused

  // Starts a stream at `start` bytes into `region` (region and start must be
  // aligned: checked, kMisaligned).
  WriteResult begin(FlashDevice& device, const FlashRegion& region, std::uint32_t start) noexcept;
  WriteResult append(std::span<const std::uint8_t> bytes) noexcept;
  // Programs the held partial unit padded with 0xFF.
  WriteResult finish() noexcept;
  // Programs `bytes` at `at` bytes into the region, below the stream's
  // start; erases the sector first if the stream has not reached it.
  WriteResult write_at(std::uint32_t at, std::span<const std::uint8_t> bytes) noexcept;

  // Worst-case time of appending `bytes` now: the erases it triggers plus
  // programming, ms (rounded up).
  std::uint32_t estimate_append_ms(std::size_t bytes) const noexcept;
  // Bytes accepted by append() so far (held ones included).
  std::uint32_t appended() const noexcept { return position_ + static_cast<std::uint32_t>(held_) - start_; }

 private:
  WriteResult program_range(std::uint32_t at, std::span<const std::uint8_t> bytes) noexcept;
  WriteResult ensure_erased(std::uint32_t end) noexcept;

  FlashDevice* device_ = nullptr;
  FlashRegion region_{};
  std::uint32_t alignment_ = 1;
  std::uint32_t start_ = 0;        // region offset where the stream began
  std::uint32_t position_ = 0;     // region offset of the next unit to program
  std::uint32_t erased_end_ = 0;   // region offsets [0, erased_end_) are erased by us
  std::uint8_t held_bytes_[kMaxAlignment] = {};
  std::size_t held_ = 0;
};

}  // namespace hadynet::flash

#endif  // HADYNET_FIRMWARE_FLASH_FLASH_REGION_WRITER_H_
