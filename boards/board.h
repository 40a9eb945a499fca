// The board interface (docs/architecture.md §6 and "Seams of the firmware"): everything the
// portable firmware (firmware/app/) needs from the hardware, and nothing
// more. Each board directory (boards/mps2-an386/, boards/stm32f405/)
// implements it; the build links exactly one of them into an image, so no
// portable code ever says #ifdef BOARD.
//
// Threading: everything here is called from the main loop only (thread
// mode). The SysTick interrupt updates the tick count and the period flag.
#ifndef HADYNET_BOARDS_BOARD_H_
#define HADYNET_BOARDS_BOARD_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/flash/flash_device.h"
#include "firmware/flash/flash_region_writer.h"

namespace hadynet::board {

// The control period: period_elapsed() turns true every 1 / kPeriodHz s.
inline constexpr std::uint32_t kPeriodHz = 5;

// Static description of the board, from its board.cmake (the one place
// that holds its memory sizes and clocks; generated into board_config.h).
struct Description {
  const char* name;              // e.g. "mps2-an386"
  std::uint32_t core_clock_hz;   // CPU clock the board runs at after init()
  std::uint32_t tick_hz;         // rate of ticks()
  std::uint32_t flash_bytes;     // code + constant memory
  std::uint32_t ram_bytes;       // data memory (all RAM regions together)
};
const Description& description() noexcept;

// Clocks, SysTick (tick count and the 5 Hz period), the UART and the
// board's sensors. Called once, first thing in main().
void init() noexcept;

// Free-running count of SysTick clock cycles (description().tick_hz per
// second) since init(); wraps at 2^32. Differences of two readings are
// exact while they are below 2^32 ticks (171 s at 25 MHz, 25 s at 168 MHz).
std::uint32_t ticks() noexcept;

// True once per control period (5 Hz): returns true at most once for each
// period boundary passed since the last call. Missed boundaries (the loop was
// busy longer than a period) are counted in overrun_periods().
bool period_elapsed() noexcept;
std::uint32_t overrun_periods() noexcept;

// One received byte, without waiting: true and `byte` set if one was
// available. Bytes arriving while nobody reads may be lost (a one-byte
// hardware buffer); the link protocol's framing and CRC catch that.
bool uart_read_byte(std::uint8_t& byte) noexcept;

// Sends `size` bytes; returns when the last one is in the transmitter.
void uart_write(const std::uint8_t* data, std::size_t size) noexcept;

// The board's loadcell readings, in newtons; reading k is the model's
// channel "<board group><k>" (the model's robot profile; for the hand fc<k>:
// firmware/app/channel_layout.h). The board scans config::kLoadcells of them
// (board_config.h, from BOARD_LOADCELLS in its board.cmake; an image checks
// that the model has as many at compile time), and the scaling from the
// sensor to newtons is the board's data (boards/<board>/). False (and
// `newtons` unchanged) if `newtons` does not hold exactly config::kLoadcells
// readings or no complete scan has arrived yet. mps2-an386 has no ADC and
// returns synthetic readings.
bool read_loadcells(std::span<float> newtons) noexcept;

// The flash that holds the two model slots (docs/model-update.md): the
// device behind the flash seam, the two equal sector-aligned slot regions,
// and the device's memory-mapped view (offset 0 = its first byte), from
// which the runtime reads the booted model in place. nullptr on a board
// without one (mps2-an386: its "flash" is RAM in QEMU; it runs the
// compiled-in model). Everything lives in static storage.
struct ModelFlash {
  flash::FlashDevice& device;
  flash::FlashRegion slot_a;
  flash::FlashRegion slot_b;
  std::span<const std::uint8_t> mapped;
};
const ModelFlash* model_flash() noexcept;

// Bytes of stack the firmware has used so far (high-water mark of a pattern
// painted at reset), and the stack's size.
std::size_t stack_used_bytes() noexcept;
std::size_t stack_size_bytes() noexcept;

// Ends the program with an exit code. Under QEMU (-semihosting) this is the
// emulator's exit status (semihosting SYS_EXIT_EXTENDED); on hardware without
// a debugger the semihosting call faults into the halting fault handler.
[[noreturn]] void exit(int code) noexcept;

}  // namespace hadynet::board

#endif  // HADYNET_BOARDS_BOARD_H_
