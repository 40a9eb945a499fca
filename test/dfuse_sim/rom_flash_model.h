// The STM32F405's 1 MiB embedded flash as the ROM bootloader sees it, in
// RAM: the sector map and worst-case erase times of
// firmware/flash/stm32f405_flash_layout.h, addresses as the CPU sees them
// (0x08000000 ..), erased bytes read 0xFF and programming only clears bits
// (cell = cell AND data, like NOR hardware: the F405's controller does not
// refuse a write over programmed cells). One fault: a leaky cell whose
// `mask` bits read 1 again right after it is programmed (charge lost after
// the ROM's program check), so only a later read-back sees the difference.
#ifndef HADYNET_TEST_DFUSE_SIM_ROM_FLASH_MODEL_H_
#define HADYNET_TEST_DFUSE_SIM_ROM_FLASH_MODEL_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "firmware/flash/stm32f405_flash_layout.h"

namespace hadynet::usb::host_testing {

class RomFlashModel {
 public:
  static constexpr std::uint32_t kBase = flash::stm32f405::kFlashBase;  // CPU address of byte 0
  static constexpr std::uint32_t kSize = flash::stm32f405::kFlashSize;  // bytes

  RomFlashModel() : cells_(kSize, 0xFF) {}

  // True if [address, address + n) lies inside the flash.
  static bool contains(std::uint32_t address, std::size_t n = 1) noexcept;
  // The index of the sector holding `address` (flash::stm32f405::kSectors),
  // or nullopt outside the flash.
  static std::optional<std::size_t> sector_at(std::uint32_t address) noexcept;
  static const flash::FlashSector& sector(std::size_t index) noexcept { return flash::stm32f405::kSectors[index]; }
  static constexpr std::size_t sector_count() noexcept { return flash::stm32f405::kSectors.size(); }

  // Erases one sector (all bytes 0xFF); counts it.
  void erase_sector(std::size_t index) noexcept;
  // Programs `data` at `address` (inside the flash: the caller checks) by
  // AND. Returns true if every cell now holds its byte (no 0 bit had to
  // become 1); the leaky cell then loses its bits.
  bool program(std::uint32_t address, std::span<const std::uint8_t> data) noexcept;
  // Copies flash bytes out (inside the flash: the caller checks).
  void read(std::uint32_t address, std::span<std::uint8_t> out) const noexcept;

  // Test access: the cells (index 0 = kBase), and a fill that bypasses the
  // NOR rules (e.g. a pattern that must survive an erase of other sectors).
  std::span<const std::uint8_t> cells() const noexcept { return cells_; }
  void fill(std::uint32_t address, std::span<const std::uint8_t> bytes) noexcept;
  void set_leaky_cell(std::uint32_t address, std::uint8_t mask) noexcept {
    leaky_address_ = address;
    leaky_mask_ = mask;
  }

  std::size_t erase_count() const noexcept { return erases_; }
  // Per sector: erases since construction.
  std::size_t erases_of(std::size_t index) const noexcept { return sector_erases_[index]; }

 private:
  std::vector<std::uint8_t> cells_;
  std::size_t erases_ = 0;
  std::size_t sector_erases_[flash::stm32f405::kSectors.size()] = {};
  std::uint32_t leaky_address_ = 0;
  std::uint8_t leaky_mask_ = 0;  // 0: no leaky cell
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_DFUSE_SIM_ROM_FLASH_MODEL_H_
