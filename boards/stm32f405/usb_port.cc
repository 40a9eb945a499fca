// stm32f405's USB device port (boards/board_usb.h): the OTG FS driver on
// PA11/PA12 without VBUS sensing (PA9 is USART1 TX on this board, and a
// device powered by its own supply sees VBUS only when plugged: the host
// then finds the pull-up), the ROM bootloader as the DFU_DETACH target, and
// the 96-bit unique ID as the serial number. The model slots behind the DFU
// model interface are model_flash.cc's, managed by the application's
// ModelSlots (firmware/app/usb_link.h).
//
// The driver is polled from the main loop (usb_poll()); the OTG_FS
// interrupt stays disabled. At most one main-loop pass (one control period's
// work, ~0.1 s worst case) lies between the core's events and their
// handling: the core NAKs meanwhile, which USB hosts retry (a control
// transfer may take up to 5 s by USB 2.0 §9.2.6.4).
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "board_config.h"
#include "boards/board.h"
#include "boards/board_usb.h"
#include "boards/stm32f405/otg_fs_controller.h"
#include "boards/stm32f405/system_bootloader.h"

namespace hadynet::board {
namespace {

// RM0090 §39.1: the 96-bit unique device ID, read-only, 12 bytes.
constexpr std::uintptr_t kUniqueIdAddress = 0x1FFF7A10;

stm32::otg::OtgFsMmio g_otg_registers;
stm32::Stm32f405OtgFsHooks g_otg_hooks;
stm32::OtgFsController<stm32::otg::OtgFsMmio> g_otg(g_otg_registers, g_otg_hooks,
                                                     stm32::OtgFsOptions{.vbus_sensing = false,
                                                                         .ahb_clock_hz = config::kCoreClockHz});
stm32::SystemBootloaderDetach g_detach;

std::uint8_t g_unique_id[usb::kUniqueIdBytes];

const UsbPort kPort{g_otg, g_detach, std::span<const std::uint8_t, usb::kUniqueIdBytes>(g_unique_id)};

// True once the core, clocked, reports its AHB master idle (GRSTCTL.AHBIDL,
// 1 whenever the core is idle after a reset; RM0090 §34.16.3), within a
// bounded number of reads. An emulator that maps no OTG FS core (QEMU's
// netduinoplus2 reads zeros there) never does.
bool core_answers() noexcept {
  g_otg_hooks.enable_clocks_and_pins();
  for (std::uint32_t read = 0; read < decltype(g_otg)::kPollLimit; ++read) {
    if ((g_otg_registers.read(stm32::otg::kGrstctl) & stm32::otg::kGrstctlAhbIdle) != 0) return true;
  }
  return false;
}

}  // namespace

const UsbPort* usb_port() noexcept {
  if (!core_answers()) return nullptr;
  // The unique ID, as the MCU stores it (byte 0 at the lowest address). Read
  // only on the real MCU: QEMU maps nothing there (a bus fault).
  const auto* id = reinterpret_cast<const volatile std::uint8_t*>(kUniqueIdAddress);
  for (std::size_t i = 0; i < usb::kUniqueIdBytes; ++i) g_unique_id[i] = id[i];
  return &kPort;
}

void usb_poll() noexcept { g_otg.poll(); }

}  // namespace hadynet::board
