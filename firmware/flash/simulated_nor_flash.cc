#include "firmware/flash/simulated_nor_flash.h"

namespace hadynet::flash {

SimulatedNorFlash::SimulatedNorFlash(std::span<const FlashSector> sectors, std::span<std::uint8_t> storage,
                                     std::uint32_t program_alignment, std::uint32_t program_max_us_per_byte) noexcept
    : sectors_(sectors),
      storage_(storage),
      alignment_(program_alignment == 0 ? 1 : program_alignment),
      program_us_per_byte_(program_max_us_per_byte) {
  for (std::uint8_t& b : storage_) b = 0xFF;
}

SimulatedNorFlash::Fault SimulatedNorFlash::next_operation() noexcept {
  ++operations_;
  if (power_cut_at_ != 0 && operations_ == power_cut_at_) return Fault::kPowerCut;
  if (write_error_at_ != 0 && operations_ == write_error_at_) return Fault::kWriteError;
  return Fault::kNone;
}

FlashStatus SimulatedNorFlash::erase_sector(std::size_t index) noexcept {
  if (!powered_) return FlashStatus::kPowerLoss;
  if (index >= sectors_.size()) return FlashStatus::kOutOfRange;
  const FlashSector& s = sectors_[index];
  if (s.offset + static_cast<std::size_t>(s.size) > storage_.size()) return FlashStatus::kOutOfRange;
  const Fault fault = next_operation();
  if (fault == Fault::kWriteError) return FlashStatus::kWriteError;
  const std::uint32_t n = fault == Fault::kPowerCut ? s.size / 2 : s.size;
  for (std::uint32_t i = 0; i < n; ++i) storage_[s.offset + i] = 0xFF;
  ++erases_;
  if (fault == Fault::kPowerCut) {
    powered_ = false;
    return FlashStatus::kPowerLoss;
  }
  return FlashStatus::kOk;
}

FlashStatus SimulatedNorFlash::program(std::uint32_t offset, std::span<const std::uint8_t> data) noexcept {
  if (!powered_) return FlashStatus::kPowerLoss;
  if (offset > storage_.size() || data.size() > storage_.size() - offset) return FlashStatus::kOutOfRange;
  if (offset % alignment_ != 0 || data.size() % alignment_ != 0) return FlashStatus::kMisaligned;
  if (data.empty()) return FlashStatus::kOk;
  const std::size_t first = sector_of(sectors_, offset);
  const std::size_t last = sector_of(sectors_, static_cast<std::uint32_t>(offset + data.size() - 1));
  if (first == sectors_.size() || last == sectors_.size()) return FlashStatus::kOutOfRange;
  if (first != last) return FlashStatus::kCrossesSector;
  for (std::size_t i = 0; i < data.size(); ++i) {
    if (storage_[offset + i] != 0xFF) return FlashStatus::kNotErased;
  }
  const Fault fault = next_operation();
  if (fault == Fault::kWriteError) return FlashStatus::kWriteError;
  const std::size_t n = fault == Fault::kPowerCut ? data.size() / 2 : data.size();
  for (std::size_t i = 0; i < n; ++i) storage_[offset + i] &= data[i];  // NOR: bits only cleared
  if (fault == Fault::kPowerCut) {
    powered_ = false;
    return FlashStatus::kPowerLoss;
  }
  return FlashStatus::kOk;
}

FlashStatus SimulatedNorFlash::read(std::uint32_t offset, std::span<std::uint8_t> out) const noexcept {
  if (!powered_) return FlashStatus::kPowerLoss;
  if (offset > storage_.size() || out.size() > storage_.size() - offset) return FlashStatus::kOutOfRange;
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = storage_[offset + i];
  return FlashStatus::kOk;
}

}  // namespace hadynet::flash
