// Cortex-M start-up shared by every board: the core part of the vector
// table, Reset_Handler (the board's early-boot hook, FPU on, .data copied, .bss zeroed, stack painted,
// static constructors, main) and the default exception handlers, which halt.
// The board appends its interrupt vectors (section .isr_vector.irq, right
// after this table; see sections.ld). There is no heap: the linker script
// defines no heap region and nothing here or in the board provides _sbrk.
//
// Compiled with -fno-tree-loop-distribute-patterns (boards/CMakeLists.txt)
// so the start-up loops stay loops instead of becoming memcpy/memset calls.
#include <cstddef>
#include <cstdint>

#include "boards/board.h"
#include "boards/common/cortex_m.h"

// Symbols of the linker script (boards/common/sections.ld).
extern "C" {
extern std::uint32_t __data_load__[];  // .data's initial values in flash
extern std::uint32_t __data_start__[];
extern std::uint32_t __data_end__[];
extern std::uint32_t __bss_start__[];
extern std::uint32_t __bss_end__[];
extern std::uint32_t __stack_limit__[];  // lowest stack address
extern std::uint32_t __stack_top__[];    // initial stack pointer
using InitFunction = void (*)();
extern InitFunction __preinit_array_start[];
extern InitFunction __preinit_array_end[];
extern InitFunction __init_array_start[];
extern InitFunction __init_array_end[];
}

// The application's main(), called under another name: C++ forbids calling
// main itself.
extern "C" int application_main() asm("main");

namespace {

constexpr std::uint32_t kStackPaint = 0xA5A5A5A5u;

// Exception number (IPSR) of the fault or unexpected interrupt that halted
// the program, for a debugger; 0 while running.
volatile std::uint32_t g_halted_exception = 0;

}  // namespace

extern "C" {

[[noreturn]] void Default_Handler() {
  std::uint32_t ipsr;
  asm volatile("mrs %0, ipsr" : "=r"(ipsr));
  g_halted_exception = ipsr & 0x1FFu;
  hadynet::board::cortex_m::disable_interrupts();
  for (;;) asm volatile("wfi");
}

// Every core exception the firmware does not use halts in Default_Handler;
// a board or the common code overrides one by defining the strong symbol.
#define HADYNET_WEAK_HANDLER(name) \
  __attribute__((weak)) void name() { Default_Handler(); }
HADYNET_WEAK_HANDLER(NMI_Handler)
HADYNET_WEAK_HANDLER(HardFault_Handler)
HADYNET_WEAK_HANDLER(MemManage_Handler)
HADYNET_WEAK_HANDLER(BusFault_Handler)
HADYNET_WEAK_HANDLER(UsageFault_Handler)
HADYNET_WEAK_HANDLER(SVC_Handler)
HADYNET_WEAK_HANDLER(DebugMon_Handler)
HADYNET_WEAK_HANDLER(PendSV_Handler)
HADYNET_WEAK_HANDLER(SysTick_Handler)
#undef HADYNET_WEAK_HANDLER

[[noreturn]] void Reset_Handler();

// The board's first word at reset, before the FPU, the vector table offset,
// .data and .bss are set up (so it may read only .noinit and registers, and
// must not rely on static initialisers). It may leave for another program
// (stm32f405: the ROM bootloader after a DFU_DETACH). Default: nothing.
__attribute__((weak)) void hadynet_board_early_boot() {}

// ARMv7-M B1.5.3: word 0 is the initial stack pointer, words 1..15 the
// system exceptions; the board's external interrupts follow.
struct CoreVectorTable {
  const void* initial_sp;
  void (*handlers[15])();
};

__attribute__((section(".isr_vector.core"), used)) const CoreVectorTable g_core_vectors = {
    __stack_top__,
    {
        Reset_Handler,
        NMI_Handler,
        HardFault_Handler,
        MemManage_Handler,
        BusFault_Handler,
        UsageFault_Handler,
        nullptr,
        nullptr,
        nullptr,
        nullptr,
        SVC_Handler,
        DebugMon_Handler,
        nullptr,
        PendSV_Handler,
        SysTick_Handler,
    },
};

[[noreturn]] void Reset_Handler() {
  namespace cm = hadynet::board::cortex_m;
  hadynet_board_early_boot();
  // The FPU first: the code below and everything after may use it.
  cm::reg(cm::kScbCpacr) |= cm::kCpacrCp10Cp11Full;
  cm::data_sync_barrier();
  cm::instruction_sync_barrier();
  cm::reg(cm::kScbVtor) = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(&g_core_vectors));
  cm::reg(cm::kScbCcr) |= cm::kCcrDiv0Trap;

  for (std::uint32_t *src = __data_load__, *dst = __data_start__; dst < __data_end__;) *dst++ = *src++;
  for (std::uint32_t* dst = __bss_start__; dst < __bss_end__;) *dst++ = 0;

  // Paint the unused stack (below this frame, with a margin) for
  // stack_used_bytes().
  std::uint32_t* sp;
  asm volatile("mov %0, sp" : "=r"(sp));
  for (std::uint32_t* p = __stack_limit__; p < sp - 16;) *p++ = kStackPaint;

  for (InitFunction* f = __preinit_array_start; f < __preinit_array_end; ++f) (*f)();
  for (InitFunction* f = __init_array_start; f < __init_array_end; ++f) (*f)();

  hadynet::board::exit(application_main());
}

}  // extern "C"

namespace hadynet::board {

std::size_t stack_size_bytes() noexcept {
  return static_cast<std::size_t>(reinterpret_cast<std::uintptr_t>(__stack_top__) -
                                  reinterpret_cast<std::uintptr_t>(__stack_limit__));
}

std::size_t stack_used_bytes() noexcept {
  const std::uint32_t* p = __stack_limit__;
  while (p < __stack_top__ && *p == kStackPaint) ++p;
  return static_cast<std::size_t>(reinterpret_cast<std::uintptr_t>(__stack_top__) -
                                  reinterpret_cast<std::uintptr_t>(p));
}

}  // namespace hadynet::board
