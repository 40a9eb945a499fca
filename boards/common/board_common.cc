// The parts of the board interface every Cortex-M board shares: the SysTick
// tick count and 5 Hz period flag, and exit() through semihosting.
#include <cstdint>

#include "boards/board.h"
#include "boards/common/cortex_m.h"

namespace hadynet::board {
namespace {

namespace cm = cortex_m;

constexpr std::uint32_t kInterruptsPerPeriod = cm::kSysTickHz / kPeriodHz;
static_assert(cm::kSysTickHz % kPeriodHz == 0, "the period must be a whole number of SysTick interrupts");

// SysTick state: written by the interrupt, read by the main loop. 32-bit
// loads and stores are single-copy atomic on the Cortex-M4.
volatile std::uint32_t g_systick_interrupts = 0;  // since start_systick()
volatile std::uint32_t g_periods = 0;             // period boundaries passed
std::uint32_t g_reload = 0;                       // SysTick reload value (cycles per interrupt - 1)
std::uint32_t g_periods_seen = 0;                 // main loop's view of g_periods
std::uint32_t g_overruns = 0;

}  // namespace

namespace cortex_m {

void start_systick(std::uint32_t core_clock_hz) noexcept {
  g_reload = core_clock_hz / kSysTickHz - 1;
  reg(kSystCsr) = 0;
  reg(kSystRvr) = g_reload <= kSystMaxReload ? g_reload : kSystMaxReload;
  reg(kSystCvr) = 0;  // any write clears the counter: the first interrupt comes one reload later
  // SysTick at the lowest priority (0xF0 in the top byte of SHPR3).
  reg(kScbShpr3) = (reg(kScbShpr3) & 0x00FFFFFFu) | (0xF0u << 24);
  reg(kSystCsr) = kSystCsrClkSourceCpu | kSystCsrTickInt | kSystCsrEnable;
  enable_interrupts();
}

void delay_cycles(std::uint32_t cycles) noexcept {
  // About 3 cycles per iteration (subs + bne taken).
  for (std::uint32_t i = cycles / 3; i > 0; --i) asm volatile("" ::: "memory");
}

}  // namespace cortex_m

std::uint32_t ticks() noexcept {
  std::uint32_t interrupts;
  std::uint32_t value;
  {
    cm::InterruptLock lock;
    interrupts = g_systick_interrupts;
    value = cm::reg(cm::kSystCvr);
    // The counter may have wrapped after the interrupt count was read, with
    // its interrupt still pending (masked here): count that wrap, and read
    // the counter again so it is certainly after the wrap.
    if ((cm::reg(cm::kScbIcsr) & cm::kIcsrPendStSet) != 0) {
      ++interrupts;
      value = cm::reg(cm::kSystCvr);
    }
  }
  return interrupts * (g_reload + 1) + (g_reload - value);
}

bool period_elapsed() noexcept {
  const std::uint32_t periods = g_periods;
  if (periods == g_periods_seen) return false;
  g_overruns += periods - g_periods_seen - 1;
  g_periods_seen = periods;
  return true;
}

std::uint32_t overrun_periods() noexcept { return g_overruns; }

// Semihosting (Arm "Semihosting for AArch32 and AArch64", SYS_EXIT_EXTENDED
// 0x20): r0 = operation, r1 = address of {reason, exit code};
// ADP_Stopped_ApplicationExit = 0x20026. On M-profile the call is BKPT 0xAB.
[[noreturn]] void exit(int code) noexcept {
  constexpr std::uint32_t kSysExitExtended = 0x20;
  constexpr std::uint32_t kApplicationExit = 0x20026;
  const std::uint32_t block[2] = {kApplicationExit, static_cast<std::uint32_t>(code)};
  register std::uint32_t r0 asm("r0") = kSysExitExtended;
  register const std::uint32_t* r1 asm("r1") = block;
  asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  // Not under a semihosting host (or it returned): halt.
  cm::disable_interrupts();
  for (;;) asm volatile("wfi");
}

}  // namespace hadynet::board

extern "C" void SysTick_Handler() {
  using namespace hadynet::board;
  const std::uint32_t n = g_systick_interrupts + 1;
  g_systick_interrupts = n;
  if (n % kInterruptsPerPeriod == 0) g_periods = g_periods + 1;
}
