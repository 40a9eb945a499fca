#include "boards/stm32f405/clock_tree.h"

#include <cstdint>

#include "boards/common/cortex_m.h"
#include "boards/stm32f405/stm32f405_registers.h"

namespace hadynet::board::stm32 {
namespace {

using cortex_m::reg;

// Polls until (reg & mask) == want or about `tries` reads have passed.
bool wait_for(std::uintptr_t address, std::uint32_t mask, std::uint32_t want, std::uint32_t tries) noexcept {
  for (std::uint32_t i = 0; i < tries; ++i) {
    if ((reg(address) & mask) == want) return true;
  }
  return false;
}

// HSE start-up is specified as at most 2 ms for common crystals; 100 000
// polls of a peripheral register at 16 MHz are well above that.
constexpr std::uint32_t kStartupTries = 100000;

}  // namespace

Clocks configure_clocks() noexcept {
  if ((reg(kRccCr) & kRccCrHsiRdy) == 0) {
    // Out of reset the HSI runs and is ready; a clock controller that says
    // otherwise is not there (QEMU's netduinoplus2).
    return {ClockSource::kNoRcc, kSysclkHz, kSysclkHz / kApb2Divider};
  }
  const Clocks fallback = {ClockSource::kHsiFallback, kHsiHz, kHsiHz};

  reg(kRccCr) |= kRccCrHseOn;
  if (!wait_for(kRccCr, kRccCrHseRdy, kRccCrHseRdy, kStartupTries)) {
    reg(kRccCr) &= ~kRccCrHseOn;
    return fallback;
  }

  // Regulator scale 1, then the flash wait states for 168 MHz before the
  // clock goes up.
  reg(kRccApb1Enr) |= kRccApb1EnrPwr;
  cortex_m::read_back(kRccApb1Enr);  // the enable takes effect before PWR is written
  reg(kPwrCr) |= kPwrCrVosScale1;
  reg(kFlashAcr) = kFlashAcrPrefetch | kFlashAcrICache | kFlashAcrDCache | kFlashWaitStates;
  if ((reg(kFlashAcr) & kFlashAcrLatencyMask) != kFlashWaitStates) {
    reg(kRccCr) &= ~kRccCrHseOn;
    return fallback;
  }

  // Bus prescalers: AHB /1, APB1 /4 (code 5), APB2 /2 (code 4).
  reg(kRccCfgr) = (reg(kRccCfgr) & ~((0xFu << kRccCfgrHpre) | (7u << kRccCfgrPpre1) | (7u << kRccCfgrPpre2))) |
                  (5u << kRccCfgrPpre1) | (4u << kRccCfgrPpre2);
  static_assert(kApb1Divider == 4 && kApb2Divider == 2, "prescaler codes above");

  reg(kRccPllCfgr) = (kPllM << kRccPllCfgrM) | (kPllN << kRccPllCfgrN) | (((kPllP / 2) - 1) << kRccPllCfgrP) |
                     kRccPllCfgrSrcHse | (kPllQ << kRccPllCfgrQ);
  reg(kRccCr) |= kRccCrPllOn;
  if (!wait_for(kRccCr, kRccCrPllRdy, kRccCrPllRdy, kStartupTries)) {
    reg(kRccCfgr) &= ~((7u << kRccCfgrPpre1) | (7u << kRccCfgrPpre2));
    reg(kRccCr) &= ~(kRccCrPllOn | kRccCrHseOn);
    return fallback;
  }

  reg(kRccCfgr) = (reg(kRccCfgr) & ~kRccCfgrSwMask) | kRccCfgrSwPll;
  if (!wait_for(kRccCfgr, kRccCfgrSwsMask, kRccCfgrSwsPll, kStartupTries)) {
    reg(kRccCfgr) &= ~(kRccCfgrSwMask | (7u << kRccCfgrPpre1) | (7u << kRccCfgrPpre2));
    return fallback;
  }
  return {ClockSource::kPllFromHse, kSysclkHz, kSysclkHz / kApb2Divider};
}

}  // namespace hadynet::board::stm32
