#include "test/flash_controller/fake_flash_interface.h"

#include <algorithm>

namespace hadynet::board::stm32::test {
namespace {

namespace layout = flash::stm32f405;
constexpr std::size_t kWords = layout::kFlashSize / 4;
constexpr std::uint32_t kWriteOneToClear = kFlashSrErrors | kFlashSrEop;

}  // namespace

FakeFlashInterface::FakeFlashInterface() : window(kWords, 0xFFFFFFFFu), cells_(kWords, 0xFFFFFFFFu) { reset(); }

void FakeFlashInterface::reset(std::uint32_t acr) {
  std::fill(cells_.begin(), cells_.end(), 0xFFFFFFFFu);
  std::fill(window.begin(), window.end(), 0xFFFFFFFFu);
  cr_ = kFlashCrLock;
  sr_ = 0;
  registers = FlashRegisters{acr, 0, 0, sr_, cr_, 0};
  key_stage_ = 0;
  keys_broken_ = false;
  pending_ = Pending::kNone;
  hang_ = hang_next_ = false;
  next_errors_ = pending_errors_ = 0;
  unprogrammed_word_.reset();
  unerased_word_.reset();
  clear_logs();
}

void FakeFlashInterface::clear_logs() {
  register_writes_.clear();
  window_writes_.clear();
  status_reads_ = busy_status_reads_ = 0;
  ignored_cr_writes_ = cr_writes_while_busy_ = 0;
}

void FakeFlashInterface::preset(std::uint32_t offset, std::span<const std::uint8_t> bytes) {
  auto* cell_bytes = reinterpret_cast<std::uint8_t*>(cells_.data());
  std::copy(bytes.begin(), bytes.end(), cell_bytes + offset);
  std::copy(cells_.begin(), cells_.end(), window.begin());
}

void FakeFlashInterface::set_status_flags(std::uint32_t flags) {
  sr_ |= flags;
  registers.sr = sr_;
}

void FakeFlashInterface::set_busy_polls(std::uint32_t erase_polls, std::uint32_t program_polls) {
  erase_polls_ = erase_polls;
  program_polls_ = program_polls;
}

std::vector<std::uint32_t> FakeFlashInterface::writes_to(FlashRegister reg) const {
  std::vector<std::uint32_t> values;
  for (const RegisterWrite& w : register_writes_) {
    if (w.reg == reg) values.push_back(w.value);
  }
  return values;
}

std::span<const std::uint8_t> FakeFlashInterface::cells() const noexcept {
  return {reinterpret_cast<const std::uint8_t*>(cells_.data()), cells_.size() * 4};
}

void FakeFlashInterface::on_register_write(FlashRegister reg) noexcept {
  switch (reg) {
    case FlashRegister::kAcr:
      register_writes_.push_back({reg, registers.acr});
      return;
    case FlashRegister::kKeyr: {
      const std::uint32_t key = registers.keyr;
      register_writes_.push_back({reg, key});
      if (!locked() || keys_broken_) {
        keys_broken_ = true;  // the MCU raises a bus error; CR stays locked until reset
      } else if (key_stage_ == 0 && key == kFlashKey1) {
        key_stage_ = 1;
      } else if (key_stage_ == 1 && key == kFlashKey2) {
        cr_ &= ~kFlashCrLock;
        key_stage_ = 0;
      } else {
        keys_broken_ = true;
      }
      registers.cr = cr_;
      return;
    }
    case FlashRegister::kSr: {
      const std::uint32_t written = registers.sr;
      register_writes_.push_back({reg, written});
      sr_ &= ~(written & kWriteOneToClear);
      registers.sr = sr_;
      return;
    }
    case FlashRegister::kCr: {
      const std::uint32_t written = registers.cr;
      register_writes_.push_back({reg, written});
      if ((sr_ & kFlashSrBsy) != 0) ++cr_writes_while_busy_;  // the MCU stalls the bus until BSY clears
      if (locked()) {
        ++ignored_cr_writes_;
        registers.cr = cr_;
        return;
      }
      cr_ = written;
      if ((cr_ & kFlashCrStrt) != 0) {
        if ((cr_ & kFlashCrSer) != 0 && (cr_ & kFlashCrPg) == 0) {
          pending_sector_ = (cr_ & kFlashCrSnbMask) >> kFlashCrSnb;
          start(Pending::kErase, erase_polls_);
        } else {
          sr_ |= kFlashSrPgserr;
          cr_ &= ~kFlashCrStrt;
        }
      }
      registers.cr = cr_;
      registers.sr = sr_;
      return;
    }
  }
}

void FakeFlashInterface::on_window_write(std::uint32_t offset) noexcept {
  const std::uint32_t word = window[offset / 4];
  window_writes_.push_back({offset, word, cr_});
  window[offset / 4] = cells_[offset / 4];  // the store itself changes nothing
  if (locked() || (cr_ & kFlashCrPg) == 0 || pending_ != Pending::kNone) {
    sr_ |= kFlashSrPgserr;
  } else if ((cr_ & kFlashCrPsizeMask) != kFlashCrPsizeX32) {
    sr_ |= kFlashSrPgperr;
  } else {
    pending_word_offset_ = offset;
    pending_word_ = word;
    start(Pending::kProgram, program_polls_);
  }
  registers.sr = sr_;
}

void FakeFlashInterface::on_status_read() noexcept {
  ++status_reads_;
  if ((sr_ & kFlashSrBsy) != 0 && !hang_ && --polls_left_ == 0) complete();
  if ((sr_ & kFlashSrBsy) != 0) ++busy_status_reads_;
  registers.sr = sr_;
}

void FakeFlashInterface::start(Pending operation, std::uint32_t polls) noexcept {
  pending_ = operation;
  pending_errors_ = next_errors_;
  next_errors_ = 0;
  hang_ = hang_next_;
  hang_next_ = false;
  sr_ |= kFlashSrBsy;
  polls_left_ = polls;
  if (polls == 0 && !hang_) complete();
}

void FakeFlashInterface::complete() noexcept {
  sr_ &= ~kFlashSrBsy;
  cr_ &= ~kFlashCrStrt;
  if (pending_errors_ != 0) {
    sr_ |= pending_errors_;  // the operation was not carried out
  } else if (pending_ == Pending::kErase && pending_sector_ < layout::kSectors.size()) {
    const flash::FlashSector& s = layout::kSectors[pending_sector_];
    for (std::uint32_t w = s.offset / 4; w < (s.offset + s.size) / 4; ++w) {
      if (unerased_word_ && *unerased_word_ / 4 == w) continue;
      cells_[w] = 0xFFFFFFFFu;
      window[w] = cells_[w];
    }
  } else if (pending_ == Pending::kProgram) {
    const std::uint32_t w = pending_word_offset_ / 4;
    if (!(unprogrammed_word_ && *unprogrammed_word_ / 4 == w)) cells_[w] &= pending_word_;  // NOR
    window[w] = cells_[w];
  }
  pending_ = Pending::kNone;
  pending_errors_ = 0;
  registers.sr = sr_;
  registers.cr = cr_;
}

}  // namespace hadynet::board::stm32::test
