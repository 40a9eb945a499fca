// The STM32F405's embedded flash interface as a backend of the flash seam
// (firmware/flash/flash_device.h), RM0090 section 3: unlock by the key
// sequence, x32 parallelism (PSIZE = 10b: needs VDD 2.7..3.6 V), sector
// erase, word programming, bounded busy waits, error flags, relock after
// every operation, read-back verification. Reads are loads from the mapped
// flash (offset 0 = 0x08000000).
//
// Firmware sectors. The F405 has one flash bank and executes from it: while
// an erase or a program runs, every fetch from flash stalls the bus, and
// erasing the sectors this code lives in destroys the running image. The
// firmware image owns sectors 0..7 (stm32f405_flash_layout.h) and is
// replaced by the ROM bootloader (DFU from system memory), never by this
// driver, whose job is the model slots (sectors 8..11). So erase/program of
// sectors 0..7 are refused with kOutOfRange (the seam's "not a sector this
// device may touch") unless the driver is built with FirmwareSectors::kAllow.
//
// Testability. The driver is a template on a FlashAccessHook and takes the
// register block and the memory window by reference/pointer. On the MCU
// (FlashController) they are the real addresses and the hook is
// NoFlashAccessHook, whose empty inline functions compile to nothing: the
// per-word path is a store, a barrier and status loads, no virtual or
// indirect call. On the PC a test passes a RAM copy of the register block,
// a RAM window and a hook that emulates the hardware (test/flash_controller/).
// The seam's own virtual functions are called once per operation.
#ifndef HADYNET_BOARDS_STM32F405_FLASH_CONTROLLER_H_
#define HADYNET_BOARDS_STM32F405_FLASH_CONTROLLER_H_

#include <atomic>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>

#include "boards/stm32f405/stm32f405_registers.h"
#include "firmware/flash/flash_device.h"
#include "firmware/flash/stm32f405_flash_layout.h"

namespace hadynet::board::stm32 {

// The flash interface registers, laid out as on the MCU (RM0090 §3.9) at
// kFlashAcr (0x40023C00, the peripheral's first register).
struct FlashRegisters {
  std::uint32_t acr;      // 0x00 access control: latency, caches
  std::uint32_t keyr;     // 0x04 key register (write-only)
  std::uint32_t optkeyr;  // 0x08 option key register (unused here)
  std::uint32_t sr;       // 0x0C status
  std::uint32_t cr;       // 0x10 control
  std::uint32_t optcr;    // 0x14 option control (unused here)
};
static_assert(offsetof(FlashRegisters, sr) == 0x0C && offsetof(FlashRegisters, cr) == 0x10);

inline constexpr std::uint32_t kFlashKey1 = 0x45670123;  // FLASH_KEYR, first then second
inline constexpr std::uint32_t kFlashKey2 = 0xCDEF89AB;
inline constexpr std::uint32_t kFlashAcrDCacheReset = 1u << 12;  // DCRST: only while DCEN = 0
inline constexpr std::uint32_t kFlashSrEop = 1u << 0;
inline constexpr std::uint32_t kFlashSrOperr = 1u << 1;
inline constexpr std::uint32_t kFlashSrWrperr = 1u << 4;  // sector write-protected
inline constexpr std::uint32_t kFlashSrPgaerr = 1u << 5;  // alignment (128-bit row crossed)
inline constexpr std::uint32_t kFlashSrPgperr = 1u << 6;  // access size != PSIZE
inline constexpr std::uint32_t kFlashSrPgserr = 1u << 7;  // sequence (e.g. write without PG)
inline constexpr std::uint32_t kFlashSrBsy = 1u << 16;
inline constexpr std::uint32_t kFlashSrErrors =
    kFlashSrOperr | kFlashSrWrperr | kFlashSrPgaerr | kFlashSrPgperr | kFlashSrPgserr;  // write 1 to clear
inline constexpr std::uint32_t kFlashCrPg = 1u << 0;
inline constexpr std::uint32_t kFlashCrSer = 1u << 1;
inline constexpr int kFlashCrSnb = 3;                       // bits 6:3, sector number
inline constexpr std::uint32_t kFlashCrSnbMask = 0xFu << kFlashCrSnb;
inline constexpr std::uint32_t kFlashCrPsizeX32 = 2u << 8;  // bits 9:8 = 10b
inline constexpr std::uint32_t kFlashCrPsizeMask = 3u << 8;
inline constexpr std::uint32_t kFlashCrStrt = 1u << 16;
inline constexpr std::uint32_t kFlashCrLock = 1u << 31;

// The register written, for a hook.
enum class FlashRegister : std::uint8_t { kAcr, kKeyr, kSr, kCr };

// What the driver tells the hardware model after each access. The MCU's
// hook does nothing (the silicon reacts by itself); a test's fake applies
// the access to its simulated flash.
template <class H>
concept FlashAccessHook = requires(H hook, FlashRegister reg, std::uint32_t offset) {
  { hook.after_register_write(reg) } noexcept;
  { hook.after_window_write(offset) } noexcept;  // offset: bytes from the window start
  { hook.before_status_read() } noexcept;        // every read of FLASH_SR (each busy poll)
};

struct NoFlashAccessHook {
  void after_register_write(FlashRegister) noexcept {}
  void after_window_write(std::uint32_t) noexcept {}
  void before_status_read() noexcept {}
};

enum class FirmwareSectors : bool { kRefuse, kAllow };
// The first sector outside the firmware image (model slot A).
inline constexpr std::size_t kFirstModelSector = 8;
static_assert(flash::stm32f405::kSectors[kFirstModelSector].offset == flash::stm32f405::kModelSlotAOffset);

// Busy-wait bound. One poll iteration (status load >= 2 cycles, count,
// compare, test, taken branch >= 2: six instructions at -O2) is at least
// kMinCyclesPerPoll core cycles, so `budget` polls last at least
// budget * kMinCyclesPerPoll / core_clock_hz: never shorter than the time
// the budget covers, twice the datasheet's worst case:
//   budget = ceil(2 * max_us * core_clock_hz / (1e6 * kMinCyclesPerPoll)), >= 1.
// At 168 MHz: a 128 KiB sector (4000 ms) 336e6 polls, a word (100 us) 8400.
// Note: while this code runs from flash, instruction fetches stall during
// the operation, so on the MCU the loop mostly runs after BSY has cleared;
// the count bounds a controller that stays busy without stalling the bus.
inline constexpr std::uint32_t kMinCyclesPerPoll = 4;
constexpr std::uint32_t poll_budget(std::uint64_t max_us, std::uint32_t core_clock_hz) noexcept {
  const std::uint64_t divisor = 1000000ull * kMinCyclesPerPoll;
  const std::uint64_t polls = (2 * max_us * core_clock_hz + divisor - 1) / divisor;
  if (polls == 0) return 1;
  return polls > 0xFFFFFFFFull ? 0xFFFFFFFFu : static_cast<std::uint32_t>(polls);
}
inline constexpr std::uint32_t kWordProgramMaxUs =
    flash::stm32f405::kProgramMaxUsPerByte * flash::stm32f405::kProgramAlignment;

// ---- Instantiation-independent parts (flash_controller.cc)

// Whether erase/program may touch sector `index` (< kSectors.size()).
bool sector_writable(std::size_t index, FirmwareSectors firmware) noexcept;
// The seam's program preconditions in its order: range, alignment, (empty:
// kOk), one sector, a writable sector (else kOutOfRange), target erased
// (read through the window). Reads only.
flash::FlashStatus check_program(const volatile std::uint32_t* window, std::uint32_t offset, std::size_t size,
                                 FirmwareSectors firmware) noexcept;
// True if the `words` words from byte `offset` (aligned) all read `value`.
bool window_words_are(const volatile std::uint32_t* window, std::uint32_t offset, std::size_t words,
                      std::uint32_t value) noexcept;
// True if the window from `offset` (aligned) reads `data` (size aligned).
bool window_matches(const volatile std::uint32_t* window, std::uint32_t offset,
                    std::span<const std::uint8_t> data) noexcept;
// Little-endian word of data[byte..byte+3] (the byte order of the flash).
std::uint32_t word_at(std::span<const std::uint8_t> data, std::size_t byte) noexcept;
flash::FlashStatus read_window(const volatile std::uint32_t* window, std::uint32_t offset,
                               std::span<std::uint8_t> out) noexcept;

// The MCU's register block and mapped flash.
volatile FlashRegisters& flash_interface_registers() noexcept;
volatile std::uint32_t* flash_memory_window() noexcept;

template <FlashAccessHook Hook>
class BasicFlashController final : public flash::FlashDevice {
 public:
  // `window`: the flash's first word (offset 0), 1 MiB, word-aligned.
  // `core_clock_hz`: HCLK while the driver runs (sizes the busy waits).
  BasicFlashController(volatile FlashRegisters& registers, volatile std::uint32_t* window,
                       std::uint32_t core_clock_hz, FirmwareSectors firmware = FirmwareSectors::kRefuse,
                       Hook hook = Hook{}) noexcept
      : registers_(registers), window_(window), core_clock_hz_(core_clock_hz), firmware_(firmware), hook_(hook) {}

  std::span<const flash::FlashSector> sectors() const noexcept override { return flash::stm32f405::kSectors; }
  std::uint32_t program_alignment() const noexcept override { return flash::stm32f405::kProgramAlignment; }
  std::uint32_t program_max_us_per_byte() const noexcept override {
    return flash::stm32f405::kProgramMaxUsPerByte;
  }
  flash::FlashStatus erase_sector(std::size_t index) noexcept override;
  flash::FlashStatus program(std::uint32_t offset, std::span<const std::uint8_t> data) noexcept override;
  flash::FlashStatus read(std::uint32_t offset, std::span<std::uint8_t> out) const noexcept override {
    return read_window(window_, offset, out);
  }

  // Busy-wait budgets, status polls (see poll_budget()); index < sectors().size().
  std::uint32_t erase_poll_budget(std::size_t index) const noexcept {
    return poll_budget(1000ull * flash::stm32f405::kSectors[index].erase_max_ms, core_clock_hz_);
  }
  std::uint32_t word_poll_budget() const noexcept { return poll_budget(kWordProgramMaxUs, core_clock_hz_); }

 private:
  std::uint32_t read_status() noexcept {
    hook_.before_status_read();
    return registers_.sr;
  }
  void write_register(volatile std::uint32_t& reg, FlashRegister which, std::uint32_t value) noexcept {
    reg = value;
    hook_.after_register_write(which);
  }
  // Polls FLASH_SR until BSY clears or `budget` (>= 1) polls have been
  // made; returns the last value read (BSY set: timed out).
  std::uint32_t wait_until_idle(std::uint32_t budget) noexcept {
    std::uint32_t status = kFlashSrBsy;
    for (std::uint32_t n = 0; n < budget && (status & kFlashSrBsy) != 0; ++n) status = read_status();
    return status;
  }
  flash::FlashStatus begin_operation(std::uint32_t budget) noexcept;
  flash::FlashStatus end_operation(bool completed) noexcept;
  void reset_data_cache() noexcept;

  volatile FlashRegisters& registers_;
  volatile std::uint32_t* window_;
  std::uint32_t core_clock_hz_;
  FirmwareSectors firmware_;
  [[no_unique_address]] Hook hook_;
};

// Idle check (BSY clear within `budget`; a busy controller is not touched),
// unlock (if locked: the two keys; still locked = a bad key sequence earlier,
// locked until reset), stale error flags cleared.
template <FlashAccessHook Hook>
flash::FlashStatus BasicFlashController<Hook>::begin_operation(std::uint32_t budget) noexcept {
  if ((wait_until_idle(budget) & kFlashSrBsy) != 0) return flash::FlashStatus::kWriteError;
  if ((registers_.cr & kFlashCrLock) != 0) {
    write_register(registers_.keyr, FlashRegister::kKeyr, kFlashKey1);
    write_register(registers_.keyr, FlashRegister::kKeyr, kFlashKey2);
    if ((registers_.cr & kFlashCrLock) != 0) return flash::FlashStatus::kWriteError;
  }
  write_register(registers_.sr, FlashRegister::kSr, kFlashSrErrors | kFlashSrEop);
  return flash::FlashStatus::kOk;
}

// Relocks (one write: LOCK set, PG/SER/SNB/STRT cleared), clears any error
// flag, resets the data cache (it may hold the target's old contents; the
// instruction cache is left alone: nothing executes from the model slots).
// After a time-out BSY is still set and the CR write stalls the bus until
// the controller finishes (RM0090 §3.6): only the watchdog ends a
// controller that never does.
template <FlashAccessHook Hook>
flash::FlashStatus BasicFlashController<Hook>::end_operation(bool completed) noexcept {
  const std::uint32_t errors = read_status() & kFlashSrErrors;
  write_register(registers_.cr, FlashRegister::kCr, kFlashCrLock);
  if (errors != 0) write_register(registers_.sr, FlashRegister::kSr, errors);
  reset_data_cache();
  return completed && errors == 0 ? flash::FlashStatus::kOk : flash::FlashStatus::kWriteError;
}

template <FlashAccessHook Hook>
void BasicFlashController<Hook>::reset_data_cache() noexcept {
  const std::uint32_t acr = registers_.acr;
  if ((acr & kFlashAcrDCache) == 0) return;
  const std::uint32_t disabled = acr & ~(kFlashAcrDCache | kFlashAcrDCacheReset);
  write_register(registers_.acr, FlashRegister::kAcr, disabled);
  write_register(registers_.acr, FlashRegister::kAcr, disabled | kFlashAcrDCacheReset);
  write_register(registers_.acr, FlashRegister::kAcr, disabled);
  write_register(registers_.acr, FlashRegister::kAcr, disabled | kFlashAcrDCache);
}

// SER + SNB + PSIZE, then STRT; wait up to the sector's budget; relock;
// then every word must read erased (kWriteError otherwise).
template <FlashAccessHook Hook>
flash::FlashStatus BasicFlashController<Hook>::erase_sector(std::size_t index) noexcept {
  if (index >= flash::stm32f405::kSectors.size() || !sector_writable(index, firmware_)) {
    return flash::FlashStatus::kOutOfRange;
  }
  const std::uint32_t budget = erase_poll_budget(index);
  const flash::FlashStatus started = begin_operation(budget);
  if (started != flash::FlashStatus::kOk) return started;
  const std::uint32_t command =
      kFlashCrPsizeX32 | kFlashCrSer | (static_cast<std::uint32_t>(index) << kFlashCrSnb);
  write_register(registers_.cr, FlashRegister::kCr, command);
  write_register(registers_.cr, FlashRegister::kCr, command | kFlashCrStrt);
  const flash::FlashStatus ended = end_operation((wait_until_idle(budget) & kFlashSrBsy) == 0);
  if (ended != flash::FlashStatus::kOk) return ended;
  const flash::FlashSector& sector = flash::stm32f405::kSectors[index];
  return window_words_are(window_, sector.offset, sector.size / 4, 0xFFFFFFFFu) ? flash::FlashStatus::kOk
                                                                              : flash::FlashStatus::kWriteError;
}

// PG + PSIZE, then per word: store, barrier, wait up to one word's budget,
// stop at the first error; relock; then the words must read back as `data`.
// The barrier: the store reaches the flash over the D-Code bus, the status
// load goes over the system bus; it keeps the first poll behind the store.
template <FlashAccessHook Hook>
flash::FlashStatus BasicFlashController<Hook>::program(std::uint32_t offset,
                                                       std::span<const std::uint8_t> data) noexcept {
  const flash::FlashStatus allowed = check_program(window_, offset, data.size(), firmware_);
  if (allowed != flash::FlashStatus::kOk || data.empty()) return allowed;
  const std::uint32_t budget = word_poll_budget();
  const flash::FlashStatus started = begin_operation(budget);
  if (started != flash::FlashStatus::kOk) return started;
  write_register(registers_.cr, FlashRegister::kCr, kFlashCrPsizeX32 | kFlashCrPg);
  bool completed = true;
  for (std::size_t byte = 0; byte < data.size(); byte += 4) {
    const std::uint32_t at = offset + static_cast<std::uint32_t>(byte);
    window_[at / 4] = word_at(data, byte);
    std::atomic_thread_fence(std::memory_order_seq_cst);
    hook_.after_window_write(at);
    if ((wait_until_idle(budget) & (kFlashSrBsy | kFlashSrErrors)) != 0) {
      completed = false;
      break;
    }
  }
  const flash::FlashStatus ended = end_operation(completed);
  if (ended != flash::FlashStatus::kOk) return ended;
  return window_matches(window_, offset, data) ? flash::FlashStatus::kOk : flash::FlashStatus::kWriteError;
}

// The MCU's driver: no hook, instantiated once in flash_controller.cc.
extern template class BasicFlashController<NoFlashAccessHook>;
using FlashController = BasicFlashController<NoFlashAccessHook>;

}  // namespace hadynet::board::stm32

#endif  // HADYNET_BOARDS_STM32F405_FLASH_CONTROLLER_H_
