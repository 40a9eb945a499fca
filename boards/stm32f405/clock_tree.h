// STM32F405 clock tree: 8 MHz crystal (HSE) -> main PLL -> 168 MHz SYSCLK,
// AHB 168 MHz, APB2 84 MHz (USART1, ADC1), APB1 42 MHz; flash at 5 wait
// states with prefetch and caches, regulator in scale 1.
#ifndef HADYNET_BOARDS_STM32F405_CLOCK_TREE_H_
#define HADYNET_BOARDS_STM32F405_CLOCK_TREE_H_

#include <cstdint>

#include "board_config.h"

namespace hadynet::board::stm32 {

inline constexpr std::uint32_t kHseHz = 8000000;  // crystal
inline constexpr std::uint32_t kHsiHz = 16000000;  // internal RC, the reset clock
// Main PLL: VCO input HSE / M = 1 MHz (1..2 MHz allowed), VCO = 336 MHz
// (100..432), SYSCLK = VCO / P = 168 MHz, USB clock VCO / Q = 48 MHz.
inline constexpr std::uint32_t kPllM = 8, kPllN = 336, kPllP = 2, kPllQ = 7;
inline constexpr std::uint32_t kSysclkHz = kHseHz / kPllM * kPllN / kPllP;
static_assert(kSysclkHz == config::kCoreClockHz, "PLL settings must give the board's core clock (board.cmake)");
static_assert(kHseHz / kPllM * kPllN / kPllQ == 48000000, "USB needs 48 MHz");
inline constexpr std::uint32_t kApb2Divider = 2;  // APB2 <= 84 MHz
inline constexpr std::uint32_t kApb1Divider = 4;  // APB1 <= 42 MHz
inline constexpr std::uint32_t kFlashWaitStates = 5;  // 150 < HCLK <= 168 MHz at 2.7..3.6 V

enum class ClockSource : std::uint8_t {
  kPllFromHse,   // 168 MHz as configured
  kHsiFallback,  // the crystal or the PLL did not start: 16 MHz HSI, no prescalers
  kNoRcc,        // the RCC reads as all zeros (QEMU 7.2 does not model it; its CPU runs at 168 MHz)
};

struct Clocks {
  ClockSource source;
  std::uint32_t core_hz;  // SYSCLK = HCLK
  std::uint32_t apb2_hz;  // USART1, ADC1
};

// Brings up the clock tree; every wait is bounded, so a missing crystal
// falls back to the HSI instead of hanging.
Clocks configure_clocks() noexcept;

}  // namespace hadynet::board::stm32

#endif  // HADYNET_BOARDS_STM32F405_CLOCK_TREE_H_
