// A pass-through FlashDevice that counts the erases and programmed bytes
// that reach the device underneath (for the update benchmark: erases and
// bytes per update). Only operations the device completed (kOk) count.
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_COUNTING_FLASH_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_COUNTING_FLASH_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/flash/flash_device.h"

namespace hadynet::model_update {

struct FlashCounters {
  std::uint32_t erases = 0;              // sector erases
  std::uint32_t program_operations = 0;  // program() calls
  std::uint32_t programmed_bytes = 0;    // bytes passed to program(), padding included
};

class CountingFlashDevice final : public flash::FlashDevice {
 public:
  explicit CountingFlashDevice(flash::FlashDevice& device) noexcept : device_(device) {}

  std::span<const flash::FlashSector> sectors() const noexcept override { return device_.sectors(); }
  std::uint32_t program_alignment() const noexcept override { return device_.program_alignment(); }
  std::uint32_t program_max_us_per_byte() const noexcept override { return device_.program_max_us_per_byte(); }
  flash::FlashStatus erase_sector(std::size_t index) noexcept override;
  flash::FlashStatus program(std::uint32_t offset, std::span<const std::uint8_t> data) noexcept override;
  flash::FlashStatus read(std::uint32_t offset, std::span<std::uint8_t> out) const noexcept override {
    return device_.read(offset, out);
  }

  const FlashCounters& counters() const noexcept { return counters_; }
  void reset_counters() noexcept { counters_ = {}; }

 private:
  flash::FlashDevice& device_;
  FlashCounters counters_{};
};

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_COUNTING_FLASH_H_
