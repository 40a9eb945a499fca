// Where things live inside one model slot (a sector-aligned flash region;
// the two slots have equal sizes):
//
//   slot offset  bytes  what
//   0            256    the image header (model_image.h), programmed LAST,
//                       after the payload was written, read back and hashed:
//                       an interrupted update leaves no header ("empty")
//   256          16     trial flag "tried"      (4-byte word + 12 bytes left erased)
//   272          16     trial flag "confirmed"
//   288          16     trial flag "invalid"
//   304 .. 1023         unused, erased
//   1024         n      the payload (n = the header's payload length)
//
// Trial flags: each is a 4-byte word in its own 16-byte program unit (so a
// flash with a program unit of up to 16 bytes programs it once), written
// from 0xFFFFFFFF to its magic value and never erased in place; only the
// update that rewrites the slot erases them (with its header). Reading:
//   * tried, invalid: set when the word is not 0xFFFFFFFF (any programming
//     attempt, a torn one included, counts: they only ever withdraw trust);
//   * confirmed: set only when the word equals its magic exactly (a torn
//     write grants nothing; the image is then reverted as an unconfirmed
//     trial).
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_LAYOUT_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_LAYOUT_H_

#include <cstdint>

#include "firmware/model_update/model_image.h"

namespace hadynet::model_update {

inline constexpr std::uint32_t kSlotHeaderOffset = 0;
inline constexpr std::uint32_t kSlotFlagUnitBytes = 16;  // one flag per unit
inline constexpr std::uint32_t kSlotFlagWordBytes = 4;
inline constexpr std::uint32_t kSlotPayloadOffset = 1024;
static_assert(kSlotHeaderOffset + kImageHeaderSize <= 256);

enum class TrialFlag : std::uint8_t { kTried, kConfirmed, kInvalid };

// Slot offset of a flag's word.
constexpr std::uint32_t trial_flag_offset(TrialFlag flag) noexcept {
  switch (flag) {
    case TrialFlag::kTried: return 256;
    case TrialFlag::kConfirmed: return 272;
    case TrialFlag::kInvalid: return 288;
  }
  return 288;
}

// The value a set flag's word holds (little-endian, so the bytes spell
// "TRYD", "CONF", "INVL" in a flash dump). Distinct from each other and from
// the erased 0xFFFFFFFF.
constexpr std::uint32_t trial_flag_magic(TrialFlag flag) noexcept {
  switch (flag) {
    case TrialFlag::kTried: return 0x44595254u;
    case TrialFlag::kConfirmed: return 0x464E4F43u;
    case TrialFlag::kInvalid: return 0x4C564E49u;
  }
  return 0x4C564E49u;
}

inline constexpr std::uint32_t kErasedWord = 0xFFFFFFFFu;

static_assert(trial_flag_offset(TrialFlag::kInvalid) + kSlotFlagUnitBytes <= kSlotPayloadOffset);

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_LAYOUT_H_
