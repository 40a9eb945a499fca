// The MCU side of the OTG FS driver: the board hooks (clocks, pins, the
// 25 ms wait) and the driver compiled once for the real peripheral
// (otg::OtgFsMmio).
#include "boards/stm32f405/otg_fs_controller.h"

#include <cstdint>

#include "boards/board.h"
#include "boards/common/cortex_m.h"
#include "boards/stm32f405/stm32f405_registers.h"

namespace hadynet::board::stm32 {

template class OtgFsController<otg::OtgFsMmio>;

namespace {
constexpr int kDmPin = 11, kDpPin = 12;  // PA11 = OTG_FS_DM, PA12 = OTG_FS_DP
}  // namespace

void Stm32f405OtgFsHooks::enable_clocks_and_pins() noexcept {
  using cortex_m::reg;
  reg(kRccAhb1Enr) = reg(kRccAhb1Enr) | kRccAhb1EnrGpioA;
  reg(otg::kRccAhb2Enr) = reg(otg::kRccAhb2Enr) | otg::kRccAhb2EnrOtgFs;
  cortex_m::read_back(otg::kRccAhb2Enr);
  // PA11, PA12: alternate function 10, very high speed. PA9 (VBUS) stays an
  // input: the core senses it directly when GCCFG.VBUSBSEN is set.
  const std::uintptr_t moder = kGpioA + kGpioModer;
  const std::uint32_t two_bit_fields = (3u << (2 * kDmPin)) | (3u << (2 * kDpPin));
  reg(moder) =
      (reg(moder) & ~two_bit_fields) | (kGpioModeAlternate << (2 * kDmPin)) | (kGpioModeAlternate << (2 * kDpPin));
  const std::uintptr_t ospeedr = kGpioA + otg::kGpioOspeedr;
  reg(ospeedr) = reg(ospeedr) | two_bit_fields;
  const std::uintptr_t afrh = kGpioA + kGpioAfrh;
  reg(afrh) = (reg(afrh) & ~((0xFu << (4 * (kDmPin - 8))) | (0xFu << (4 * (kDpPin - 8))))) |
              (otg::kGpioAfOtgFs << (4 * (kDmPin - 8))) | (otg::kGpioAfOtgFs << (4 * (kDpPin - 8)));
}

void Stm32f405OtgFsHooks::wait_ms(std::uint32_t ms) noexcept {
  // SysTick clock cycles (tick_hz = the core clock on this board);
  // differences are exact below 2^32 ticks (25 s at 168 MHz), so `ms` is
  // capped at 10 s. Bounded even if SysTick does not run: each pass takes
  // more than one core cycle, so wait_ticks passes last longer than `ms`.
  const std::uint32_t capped_ms = ms < 10'000 ? ms : 10'000;
  const std::uint32_t wait_ticks = capped_ms * (description().tick_hz / 1000);
  const std::uint32_t start = ticks();
  for (std::uint32_t pass = 0; pass < wait_ticks && ticks() - start < wait_ticks; ++pass) {
  }
}

}  // namespace hadynet::board::stm32
