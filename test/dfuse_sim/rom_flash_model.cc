#include "test/dfuse_sim/rom_flash_model.h"

namespace hadynet::usb::host_testing {

bool RomFlashModel::contains(std::uint32_t address, std::size_t n) noexcept {
  return address >= kBase && address - kBase <= kSize && n <= kSize - (address - kBase);
}

std::optional<std::size_t> RomFlashModel::sector_at(std::uint32_t address) noexcept {
  if (!contains(address)) return std::nullopt;
  const std::size_t i = flash::sector_of(flash::stm32f405::kSectors, address - kBase);
  if (i >= sector_count()) return std::nullopt;
  return i;
}

void RomFlashModel::erase_sector(std::size_t index) noexcept {
  const flash::FlashSector& s = sector(index);
  for (std::uint32_t i = 0; i < s.size; ++i) cells_[s.offset + i] = 0xFF;
  ++erases_;
  ++sector_erases_[index];
}

bool RomFlashModel::program(std::uint32_t address, std::span<const std::uint8_t> data) noexcept {
  const std::size_t at = address - kBase;
  bool exact = true;
  for (std::size_t i = 0; i < data.size(); ++i) {
    cells_[at + i] = static_cast<std::uint8_t>(cells_[at + i] & data[i]);
    exact = exact && cells_[at + i] == data[i];
  }
  if (leaky_mask_ != 0 && leaky_address_ >= address && leaky_address_ - address < data.size()) {
    cells_[leaky_address_ - kBase] = static_cast<std::uint8_t>(cells_[leaky_address_ - kBase] | leaky_mask_);
  }
  return exact;
}

void RomFlashModel::read(std::uint32_t address, std::span<std::uint8_t> out) const noexcept {
  const std::size_t at = address - kBase;
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = cells_[at + i];
}

void RomFlashModel::fill(std::uint32_t address, std::span<const std::uint8_t> bytes) noexcept {
  const std::size_t at = address - kBase;
  for (std::size_t i = 0; i < bytes.size(); ++i) cells_[at + i] = bytes[i];
}

}  // namespace hadynet::usb::host_testing
