#include "firmware/model_update/counting_flash.h"

namespace hadynet::model_update {

flash::FlashStatus CountingFlashDevice::erase_sector(std::size_t index) noexcept {
  const flash::FlashStatus s = device_.erase_sector(index);
  if (s == flash::FlashStatus::kOk) ++counters_.erases;
  return s;
}

flash::FlashStatus CountingFlashDevice::program(std::uint32_t offset, std::span<const std::uint8_t> data) noexcept {
  const flash::FlashStatus s = device_.program(offset, data);
  if (s == flash::FlashStatus::kOk) {
    ++counters_.program_operations;
    counters_.programmed_bytes += static_cast<std::uint32_t>(data.size());
  }
  return s;
}

}  // namespace hadynet::model_update
