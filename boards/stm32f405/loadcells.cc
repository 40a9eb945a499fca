#include "boards/stm32f405/loadcells.h"

#include <cstdint>

#include "boards/common/cortex_m.h"
#include "boards/stm32f405/stm32f405_registers.h"

namespace hadynet::board::stm32 {
namespace {

using cortex_m::reg;

// A 12-bit right-aligned conversion is never 0xFFFF: marks "not converted yet".
constexpr std::uint16_t kNotConverted = 0xFFFF;

// The DMA target. In .bss, which this board keeps in SRAM (DMA2 cannot
// reach the CCM RAM).
volatile std::uint16_t g_scan[kLoadcells];

void set_analog(std::uintptr_t gpio, int pin) noexcept {
  const std::uintptr_t moder = gpio + kGpioModer;
  reg(moder) = (reg(moder) & ~(3u << (2 * pin))) | (kGpioModeAnalog << (2 * pin));
}

}  // namespace

void start_loadcell_scan() noexcept {
  for (auto& v : g_scan) v = kNotConverted;
  reg(kRccAhb1Enr) |= kRccAhb1EnrGpioA | kRccAhb1EnrGpioB | kRccAhb1EnrDma2;
  reg(kRccApb2Enr) |= kRccApb2EnrAdc1;
  cortex_m::read_back(kRccApb2Enr);  // the clock enables take effect before the writes below

  for (const std::uint8_t ch : kLoadcellChannel) {
    if (ch <= 7) {
      set_analog(kGpioA, ch);  // IN0..IN7 = PA0..PA7
    } else if (ch <= 9) {
      set_analog(kGpioB, ch - 8);  // IN8, IN9 = PB0, PB1
    }
  }

  // DMA2 stream 0, channel 0 (ADC1): peripheral -> memory, 16 -> 16 bits,
  // memory increment, circular over the nine entries.
  reg(kDma2S0Cr) = 0;
  for (int i = 0; i < 1000 && (reg(kDma2S0Cr) & kDmaCrEnable) != 0; ++i) {
  }
  reg(kDma2S0Par) = static_cast<std::uint32_t>(kAdcDr);
  reg(kDma2S0M0ar) = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(&g_scan[0]));
  reg(kDma2S0Ndtr) = kLoadcells;
  reg(kDma2S0Cr) = (0u << kDmaCrChannel) | kDmaCrPriorityHigh | kDmaCrMem16 | kDmaCrPeriph16 | kDmaCrMemIncrement |
                   kDmaCrCircular | kDmaCrEnable;

  // ADC clock PCLK2 / 4 = 21 MHz (<= 36 MHz); 12-bit scan of the sequence.
  reg(kAdcCcr) = (reg(kAdcCcr) & ~(3u << kAdcCcrPrescaler)) | (1u << kAdcCcrPrescaler);
  reg(kAdcCr1) = kAdcCr1Scan;
  std::uint32_t smpr1 = 0, smpr2 = 0, sqr2 = 0, sqr3 = 0;
  for (int i = 0; i < kLoadcells; ++i) {
    const std::uint32_t ch = kLoadcellChannel[i];
    if (ch < 10) {
      smpr2 |= 7u << (3 * ch);  // 480 cycles: the amplifier's source impedance
    } else {
      smpr1 |= 7u << (3 * (ch - 10));
    }
    if (i < 6) {
      sqr3 |= ch << (5 * i);
    } else {
      sqr2 |= ch << (5 * (i - 6));
    }
  }
  static_assert(kLoadcells <= 12, "SQ13.. would be in SQR1");
  reg(kAdcSmpr1) = smpr1;
  reg(kAdcSmpr2) = smpr2;
  reg(kAdcSqr3) = sqr3;
  reg(kAdcSqr2) = sqr2;
  reg(kAdcSqr1) = static_cast<std::uint32_t>(kLoadcells - 1) << kAdcSqrLength;
  reg(kAdcCr2) = kAdcCr2AdOn | kAdcCr2Continuous | kAdcCr2Dma | kAdcCr2DmaContinue;
  cortex_m::delay_cycles(1000);  // ADC power-up (t_STAB <= 3 us)
  reg(kAdcCr2) = reg(kAdcCr2) | kAdcCr2SwStart;
}

bool loadcell_counts(std::uint16_t (&counts)[kLoadcells]) noexcept {
  std::uint16_t copy[kLoadcells];
  for (int i = 0; i < kLoadcells; ++i) {
    copy[i] = g_scan[i];
    if (copy[i] == kNotConverted) return false;
  }
  for (int i = 0; i < kLoadcells; ++i) counts[i] = copy[i];
  return true;
}

}  // namespace hadynet::board::stm32
