// Reading and setting a slot's trial flags (tried, confirmed, invalid;
// layout and reading rules in slot_layout.h) through the flash seam. A flag
// is set by programming its word from 0xFFFFFFFF to its magic value, never
// by erasing.
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_TRIAL_FLAGS_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_TRIAL_FLAGS_H_

#include <cstdint>

#include "firmware/flash/flash_device.h"
#include "firmware/flash/flash_region_writer.h"
#include "firmware/model_update/slot_layout.h"

namespace hadynet::model_update {

struct TrialFlags {
  bool tried = false;
  bool confirmed = false;
  bool invalid = false;
};

// Whether a flag word read from flash counts as set (slot_layout.h).
constexpr bool trial_flag_word_is_set(TrialFlag flag, std::uint32_t word) noexcept {
  if (flag == TrialFlag::kConfirmed) return word == trial_flag_magic(flag);
  return word != kErasedWord;
}

// Reads the three flags of `slot`; kOk, or the read's error (`out` then
// unspecified).
flash::FlashStatus read_trial_flags(const flash::FlashDevice& device, const flash::FlashRegion& slot,
                                    TrialFlags& out) noexcept;

// Sets `flag` of `slot`: programs the word (padded with 0xFF to the
// device's program unit, at most the flag's 16 bytes) when it reads erased;
// kOk without programming when it already reads set; kNotErased when it
// holds a torn value that does not read set (only "confirmed" can: that
// image is reverted on the next boot). Otherwise the program's status.
// Needs program_alignment() to divide 16.
flash::FlashStatus set_trial_flag(flash::FlashDevice& device, const flash::FlashRegion& slot, TrialFlag flag) noexcept;

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_TRIAL_FLAGS_H_
