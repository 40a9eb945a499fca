// DFU_DETACH on the STM32F405: reboot into the ROM DfuSe bootloader in
// system memory (AN2606: 0x1FFF0000, USB DFU on OTG FS, 0483:df11).
//
// The request crosses a software reset in two .noinit words (the request
// value and its complement, so power-on RAM contents start the bootloader
// with probability 2^-64 at most). At the next reset, before anything else
// (startup.cc's hadynet_board_early_boot), the words are cleared and the
// core jumps to the bootloader with the reset state the bootloader expects:
// HSI clock, no peripheral configured, system memory remapped at 0.
// Needs hardware (QEMU's netduinoplus2 has no system memory); docs/usb.md.
#ifndef HADYNET_BOARDS_STM32F405_SYSTEM_BOOTLOADER_H_
#define HADYNET_BOARDS_STM32F405_SYSTEM_BOOTLOADER_H_

#include <cstdint>

#include "firmware/usb/dfu_runtime.h"

namespace hadynet::board::stm32 {

inline constexpr std::uintptr_t kSystemMemory = 0x1FFF0000;  // initial SP, then the reset vector
inline constexpr std::uintptr_t kSyscfgMemrmp = 0x40013800;  // SYSCFG memory remap register
inline constexpr std::uint32_t kSyscfgMemrmpSystemFlash = 0x1;
inline constexpr std::uint32_t kRccApb2EnrSyscfg = 1u << 14;

// Records the request and resets the MCU (does not return).
[[noreturn]] void reboot_into_system_bootloader() noexcept;

// The DFU runtime's hook (firmware/usb/dfu_runtime.h): the reboot above.
// The stack calls it once the DFU_DETACH status stage has completed.
class SystemBootloaderDetach final : public usb::DetachHook {
 public:
  void detach_to_bootloader(std::uint16_t timeout_ms) noexcept override;
};

}  // namespace hadynet::board::stm32

#endif  // HADYNET_BOARDS_STM32F405_SYSTEM_BOOTLOADER_H_
