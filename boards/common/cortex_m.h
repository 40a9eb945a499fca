// Cortex-M4 core peripherals shared by every board (ARMv7-M system control
// space): SysTick, the system control block, the NVIC and the coprocessor
// access register; plus the few instructions C++ cannot express. Board
// peripherals (UARTs, clocks, ADCs) are in each board's directory.
#ifndef HADYNET_BOARDS_COMMON_CORTEX_M_H_
#define HADYNET_BOARDS_COMMON_CORTEX_M_H_

#include <cstdint>

namespace hadynet::board::cortex_m {

// A memory-mapped 32-bit register at a fixed address.
inline volatile std::uint32_t& reg(std::uintptr_t address) noexcept {
  return *reinterpret_cast<volatile std::uint32_t*>(address);
}

// Reads a register and discards the value: after a peripheral clock enable,
// makes sure the write has taken effect before the peripheral is accessed.
inline void read_back(std::uintptr_t address) noexcept {
  const std::uint32_t value = reg(address);
  static_cast<void>(value);
}

// SysTick (ARMv7-M B3.3).
inline constexpr std::uintptr_t kSystCsr = 0xE000E010;  // control and status
inline constexpr std::uintptr_t kSystRvr = 0xE000E014;  // reload value (24 bits)
inline constexpr std::uintptr_t kSystCvr = 0xE000E018;  // current value (counts down)
inline constexpr std::uint32_t kSystCsrEnable = 1u << 0;
inline constexpr std::uint32_t kSystCsrTickInt = 1u << 1;
inline constexpr std::uint32_t kSystCsrClkSourceCpu = 1u << 2;  // processor clock, not the reference clock
inline constexpr std::uint32_t kSystMaxReload = 0x00FFFFFF;

// System control block.
inline constexpr std::uintptr_t kScbIcsr = 0xE000ED04;   // interrupt control and state
inline constexpr std::uint32_t kIcsrPendStSet = 1u << 26;  // SysTick pending
inline constexpr std::uintptr_t kScbVtor = 0xE000ED08;   // vector table offset
inline constexpr std::uintptr_t kScbAircr = 0xE000ED0C;  // application interrupt and reset control
inline constexpr std::uint32_t kAircrSysResetReq = 0x05FA0000u | (1u << 2);  // VECTKEY + SYSRESETREQ
inline constexpr std::uintptr_t kScbCcr = 0xE000ED14;    // configuration and control
inline constexpr std::uint32_t kCcrDiv0Trap = 1u << 4;     // integer division by zero faults
inline constexpr std::uintptr_t kScbShpr3 = 0xE000ED20;  // priorities of PendSV (23:16) and SysTick (31:24)
inline constexpr std::uintptr_t kScbCpacr = 0xE000ED88;  // coprocessor access control
inline constexpr std::uint32_t kCpacrCp10Cp11Full = 0xFu << 20;  // full access to the FPU (CP10, CP11)

// NVIC: interrupt set-enable registers, one bit per external interrupt.
inline constexpr std::uintptr_t kNvicIser0 = 0xE000E100;
inline void nvic_enable(int irq) noexcept {
  reg(kNvicIser0 + 4u * static_cast<std::uint32_t>(irq / 32)) = 1u << (irq % 32);
}

inline void disable_interrupts() noexcept { asm volatile("cpsid i" ::: "memory"); }
inline void enable_interrupts() noexcept { asm volatile("cpsie i" ::: "memory"); }
// PRIMASK: 1 while interrupts are masked.
inline std::uint32_t primask() noexcept {
  std::uint32_t v;
  asm volatile("mrs %0, primask" : "=r"(v));
  return v;
}
inline void data_sync_barrier() noexcept { asm volatile("dsb" ::: "memory"); }
inline void instruction_sync_barrier() noexcept { asm volatile("isb" ::: "memory"); }

// Masks interrupts for the lifetime of the object and restores the previous
// PRIMASK (nests).
class InterruptLock {
 public:
  InterruptLock() noexcept : was_masked_(primask() != 0) { disable_interrupts(); }
  ~InterruptLock() {
    if (!was_masked_) enable_interrupts();
  }
  InterruptLock(const InterruptLock&) = delete;
  InterruptLock& operator=(const InterruptLock&) = delete;

 private:
  bool was_masked_;
};

// Starts SysTick on the processor clock (core_clock_hz) at kSysTickHz with
// its interrupt; the shared tick count and the 5 Hz period flag
// (board::ticks(), board::period_elapsed()) are driven from it. Boards call
// this from init() once their clock runs at core_clock_hz.
inline constexpr std::uint32_t kSysTickHz = 100;
void start_systick(std::uint32_t core_clock_hz) noexcept;

// Busy-waits about `cycles` processor cycles (start-up delays before
// SysTick runs; not precise).
void delay_cycles(std::uint32_t cycles) noexcept;

}  // namespace hadynet::board::cortex_m

#endif  // HADYNET_BOARDS_COMMON_CORTEX_M_H_
