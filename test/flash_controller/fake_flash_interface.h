// A fake STM32F405 flash interface for the driver's tests: a RAM register
// block and a RAM flash window the driver uses as if they were the MCU's,
// and a hook (FakeFlashInterface::Hook) through which the fake reacts the
// way the silicon does (RM0090 section 3):
//   * CR starts locked; KEYR accepts KEY1 then KEY2 (unlock), anything else
//     breaks the sequence (locked until reset()); while locked, CR writes
//     are ignored (counted).
//   * SR error flags and EOP are write-1-to-clear.
//   * CR with SER + STRT starts an erase of sector SNB; a word stored in the
//     window while PG is set starts programming it (cells &= word). Each
//     sets BSY for a number of status polls, then applies the operation to
//     the cells and the window. A window store without PG raises PGSERR.
//   * Scripted faults: error flags raised by the next operation (which is
//     then not applied), a next operation that never finishes, a word that
//     silently stays as it was, a word an erase silently leaves.
// Every register write is logged with its value; polls are counted.
#ifndef HADYNET_TEST_FLASH_CONTROLLER_FAKE_FLASH_INTERFACE_H_
#define HADYNET_TEST_FLASH_CONTROLLER_FAKE_FLASH_INTERFACE_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "boards/stm32f405/flash_controller.h"

namespace hadynet::board::stm32::test {

class FakeFlashInterface {
 public:
  struct RegisterWrite {
    FlashRegister reg;
    std::uint32_t value;
  };
  struct WindowWrite {
    std::uint32_t offset;  // bytes
    std::uint32_t value;
    std::uint32_t cr;  // FLASH_CR when the word was stored
  };

  // What the driver is instantiated with: forwards to the fake.
  struct Hook {
    FakeFlashInterface* fake;
    void after_register_write(FlashRegister reg) noexcept { fake->on_register_write(reg); }
    void after_window_write(std::uint32_t offset) noexcept { fake->on_window_write(offset); }
    void before_status_read() noexcept { fake->on_status_read(); }
  };

  FakeFlashInterface();

  // The driver's view: pass these to the driver.
  FlashRegisters registers{};
  std::vector<std::uint32_t> window;  // 1 MiB as words
  Hook hook() noexcept { return Hook{this}; }

  // Power-on state: erased cells, CR locked, SR clear, ACR `acr`, logs empty.
  void reset(std::uint32_t acr = 0);
  // Cells as if programmed earlier (no register activity, not logged).
  void preset(std::uint32_t offset, std::span<const std::uint8_t> bytes);
  void set_status_flags(std::uint32_t flags);  // stale flags (e.g. after reset)
  void set_busy_polls(std::uint32_t erase_polls, std::uint32_t program_polls);
  void fail_next_operation(std::uint32_t error_flags) { next_errors_ = error_flags; }
  void hang_next_operation() { hang_next_ = true; }
  void keep_word_unprogrammed(std::uint32_t offset) { unprogrammed_word_ = offset; }
  void keep_word_unerased(std::uint32_t offset) { unerased_word_ = offset; }
  void set_busy_now() { sr_ |= kFlashSrBsy; hang_ = true; registers.sr = sr_; }

  // Observations.
  const std::vector<RegisterWrite>& register_writes() const noexcept { return register_writes_; }
  std::vector<std::uint32_t> writes_to(FlashRegister reg) const;
  const std::vector<WindowWrite>& window_writes() const noexcept { return window_writes_; }
  std::uint64_t status_reads() const noexcept { return status_reads_; }
  std::uint64_t busy_status_reads() const noexcept { return busy_status_reads_; }
  std::uint32_t ignored_cr_writes() const noexcept { return ignored_cr_writes_; }
  std::uint32_t cr_writes_while_busy() const noexcept { return cr_writes_while_busy_; }
  bool locked() const noexcept { return (cr_ & kFlashCrLock) != 0; }
  bool key_sequence_broken() const noexcept { return keys_broken_; }
  std::uint32_t status() const noexcept { return sr_; }
  std::span<const std::uint8_t> cells() const noexcept;
  void clear_logs();

 private:
  enum class Pending : std::uint8_t { kNone, kErase, kProgram };

  void on_register_write(FlashRegister reg) noexcept;
  void on_window_write(std::uint32_t offset) noexcept;
  void on_status_read() noexcept;
  void start(Pending operation, std::uint32_t polls) noexcept;
  void complete() noexcept;

  std::vector<std::uint32_t> cells_;  // the flash's real contents
  std::uint32_t cr_ = kFlashCrLock;
  std::uint32_t sr_ = 0;
  int key_stage_ = 0;
  bool keys_broken_ = false;
  std::uint32_t erase_polls_ = 3;
  std::uint32_t program_polls_ = 1;
  Pending pending_ = Pending::kNone;
  std::size_t pending_sector_ = 0;
  std::uint32_t pending_word_offset_ = 0;
  std::uint32_t pending_word_ = 0;
  std::uint32_t polls_left_ = 0;
  bool hang_ = false;
  bool hang_next_ = false;
  std::uint32_t next_errors_ = 0;
  std::uint32_t pending_errors_ = 0;  // raised when the pending operation completes
  std::optional<std::uint32_t> unprogrammed_word_;
  std::optional<std::uint32_t> unerased_word_;
  std::vector<RegisterWrite> register_writes_;
  std::vector<WindowWrite> window_writes_;
  std::uint64_t status_reads_ = 0;
  std::uint64_t busy_status_reads_ = 0;
  std::uint32_t ignored_cr_writes_ = 0;
  std::uint32_t cr_writes_while_busy_ = 0;
};

}  // namespace hadynet::board::stm32::test

#endif  // HADYNET_TEST_FLASH_CONTROLLER_FAKE_FLASH_INTERFACE_H_
