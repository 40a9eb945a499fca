// The instantiation-independent half of the STM32F405 flash driver
// (preconditions, window reads and checks) and the MCU's instantiation.
#include "boards/stm32f405/flash_controller.h"

namespace hadynet::board::stm32 {

namespace layout = flash::stm32f405;
using flash::FlashStatus;

bool sector_writable(std::size_t index, FirmwareSectors firmware) noexcept {
  return index >= kFirstModelSector || firmware == FirmwareSectors::kAllow;
}

FlashStatus check_program(const volatile std::uint32_t* window, std::uint32_t offset, std::size_t size,
                          FirmwareSectors firmware) noexcept {
  if (offset > layout::kFlashSize || size > layout::kFlashSize - offset) return FlashStatus::kOutOfRange;
  if (offset % layout::kProgramAlignment != 0 || size % layout::kProgramAlignment != 0) {
    return FlashStatus::kMisaligned;
  }
  if (size == 0) return FlashStatus::kOk;
  const std::size_t first = flash::sector_of(layout::kSectors, offset);
  const std::size_t last = flash::sector_of(layout::kSectors, static_cast<std::uint32_t>(offset + size - 1));
  if (first == layout::kSectors.size() || last == layout::kSectors.size()) return FlashStatus::kOutOfRange;
  if (first != last) return FlashStatus::kCrossesSector;
  if (!sector_writable(first, firmware)) return FlashStatus::kOutOfRange;
  if (!window_words_are(window, offset, size / 4, 0xFFFFFFFFu)) return FlashStatus::kNotErased;
  return FlashStatus::kOk;
}

bool window_words_are(const volatile std::uint32_t* window, std::uint32_t offset, std::size_t words,
                      std::uint32_t value) noexcept {
  const volatile std::uint32_t* word = window + offset / 4;
  for (std::size_t i = 0; i < words; ++i) {
    if (word[i] != value) return false;
  }
  return true;
}

bool window_matches(const volatile std::uint32_t* window, std::uint32_t offset,
                    std::span<const std::uint8_t> data) noexcept {
  const volatile std::uint32_t* word = window + offset / 4;
  for (std::size_t byte = 0; byte + 4 <= data.size(); byte += 4) {
    if (word[byte / 4] != word_at(data, byte)) return false;
  }
  return true;
}

std::uint32_t word_at(std::span<const std::uint8_t> data, std::size_t byte) noexcept {
  return static_cast<std::uint32_t>(data[byte]) | static_cast<std::uint32_t>(data[byte + 1]) << 8 |
         static_cast<std::uint32_t>(data[byte + 2]) << 16 | static_cast<std::uint32_t>(data[byte + 3]) << 24;
}

// Word loads (the window's access size), split into bytes little-endian.
FlashStatus read_window(const volatile std::uint32_t* window, std::uint32_t offset,
                        std::span<std::uint8_t> out) noexcept {
  if (offset > layout::kFlashSize || out.size() > layout::kFlashSize - offset) return FlashStatus::kOutOfRange;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::uint32_t at = offset + static_cast<std::uint32_t>(i);
    out[i] = static_cast<std::uint8_t>(window[at / 4] >> (8 * (at % 4)));
  }
  return FlashStatus::kOk;
}

volatile FlashRegisters& flash_interface_registers() noexcept {
  return *reinterpret_cast<volatile FlashRegisters*>(kFlashAcr);
}

volatile std::uint32_t* flash_memory_window() noexcept {
  return reinterpret_cast<volatile std::uint32_t*>(layout::kFlashBase);
}

template class BasicFlashController<NoFlashAccessHook>;

}  // namespace hadynet::board::stm32
