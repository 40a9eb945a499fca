#include "firmware/model_update/trial_flags.h"

#include <array>

#include "firmware/core/little_endian.h"

namespace hadynet::model_update {

using firmware::get_le32;
using firmware::put_le32;

namespace {

flash::FlashStatus read_flag_word(const flash::FlashDevice& device, const flash::FlashRegion& slot, TrialFlag flag,
                                  std::uint32_t& word) noexcept {
  std::array<std::uint8_t, kSlotFlagWordBytes> bytes{};
  const flash::FlashStatus s = device.read(slot.offset + trial_flag_offset(flag), bytes);
  word = get_le32(bytes.data());
  return s;
}

}  // namespace

flash::FlashStatus read_trial_flags(const flash::FlashDevice& device, const flash::FlashRegion& slot,
                                    TrialFlags& out) noexcept {
  std::uint32_t tried = kErasedWord;
  std::uint32_t confirmed = kErasedWord;
  std::uint32_t invalid = kErasedWord;
  flash::FlashStatus s = read_flag_word(device, slot, TrialFlag::kTried, tried);
  if (s == flash::FlashStatus::kOk) s = read_flag_word(device, slot, TrialFlag::kConfirmed, confirmed);
  if (s == flash::FlashStatus::kOk) s = read_flag_word(device, slot, TrialFlag::kInvalid, invalid);
  out.tried = trial_flag_word_is_set(TrialFlag::kTried, tried);
  out.confirmed = trial_flag_word_is_set(TrialFlag::kConfirmed, confirmed);
  out.invalid = trial_flag_word_is_set(TrialFlag::kInvalid, invalid);
  return s;
}

flash::FlashStatus set_trial_flag(flash::FlashDevice& device, const flash::FlashRegion& slot, TrialFlag flag) noexcept {
  std::uint32_t word = kErasedWord;
  const flash::FlashStatus r = read_flag_word(device, slot, flag, word);
  if (r != flash::FlashStatus::kOk) return r;
  if (trial_flag_word_is_set(flag, word)) return flash::FlashStatus::kOk;
  if (word != kErasedWord) return flash::FlashStatus::kNotErased;
  const std::uint32_t alignment = device.program_alignment();
  if (alignment == 0 || kSlotFlagUnitBytes % alignment != 0) return flash::FlashStatus::kMisaligned;
  const std::uint32_t unit = alignment < kSlotFlagWordBytes ? kSlotFlagWordBytes : alignment;
  std::array<std::uint8_t, kSlotFlagUnitBytes> bytes{};
  bytes.fill(0xFF);
  put_le32(bytes.data(), trial_flag_magic(flag));
  return device.program(slot.offset + trial_flag_offset(flag), std::span<const std::uint8_t>(bytes.data(), unit));
}

}  // namespace hadynet::model_update
