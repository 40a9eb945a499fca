// The reboot into the ROM bootloader (system_bootloader.h).
#include "boards/stm32f405/system_bootloader.h"

#include <cstdint>

#include "boards/common/cortex_m.h"
#include "boards/stm32f405/stm32f405_registers.h"

namespace hadynet::board::stm32 {
namespace {

constexpr std::uint32_t kRequest = 0xDF11B007u;  // "DFU boot"

// Kept across the software reset (sections.ld's .noinit).
__attribute__((section(".noinit"))) volatile std::uint32_t g_boot_request[2];

}  // namespace

[[noreturn]] void reboot_into_system_bootloader() noexcept {
  cortex_m::disable_interrupts();
  g_boot_request[0] = kRequest;
  g_boot_request[1] = ~kRequest;
  cortex_m::data_sync_barrier();
  cortex_m::reg(cortex_m::kScbAircr) = cortex_m::kAircrSysResetReq;
  cortex_m::data_sync_barrier();
  for (;;) {
  }
}

void SystemBootloaderDetach::detach_to_bootloader(std::uint16_t) noexcept {
  // bitWillDetach: the device leaves the bus itself; the reset drops the
  // pull-up at once, so the host's wDetachTimeOut does not matter here.
  reboot_into_system_bootloader();
}

}  // namespace hadynet::board::stm32

// Runs first at reset (boards/common/startup.cc): .data and .bss are not
// set up yet; only the .noinit words and registers are touched.
extern "C" void hadynet_board_early_boot() {
  using namespace hadynet::board;
  if (stm32::g_boot_request[0] != stm32::kRequest || stm32::g_boot_request[1] != ~stm32::kRequest) return;
  stm32::g_boot_request[0] = 0;
  stm32::g_boot_request[1] = 0;
  cortex_m::reg(stm32::kRccApb2Enr) = cortex_m::reg(stm32::kRccApb2Enr) | stm32::kRccApb2EnrSyscfg;
  cortex_m::read_back(stm32::kRccApb2Enr);
  cortex_m::reg(stm32::kSyscfgMemrmp) = stm32::kSyscfgMemrmpSystemFlash;
  cortex_m::data_sync_barrier();
  cortex_m::instruction_sync_barrier();
  const auto* vectors = reinterpret_cast<const volatile std::uint32_t*>(stm32::kSystemMemory);
  const std::uint32_t stack = vectors[0];
  const std::uint32_t entry = vectors[1];
  asm volatile(
      "msr msp, %0\n"
      "bx %1\n" ::"r"(stack),
      "r"(entry)
      : "memory");
  __builtin_unreachable();
}
