// What the device knows about its model slots and what it booted: the
// values ModelSlots (model_slots.h) reports to the USB/link layer.
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_STATUS_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_STATUS_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/model_update/update_error.h"

namespace hadynet::model_update {

enum class SlotId : std::uint8_t { kA = 0, kB = 1 };
inline constexpr std::size_t kSlotCount = 2;

constexpr SlotId other_slot(SlotId s) noexcept { return s == SlotId::kA ? SlotId::kB : SlotId::kA; }
constexpr std::size_t slot_index(SlotId s) noexcept { return static_cast<std::size_t>(s); }

// A slot's state, as found by the last check (boot, or the end of an update
// into it) and the flag writes since.
enum class SlotState : std::uint8_t {
  kEmpty,      // no header (erased, or an update into it did not finish)
  kValid,      // a verified image for this firmware, not yet tried
  kTried,      // verified, tried, not confirmed (on trial in this boot, or it crashed in an earlier trial)
  kConfirmed,  // verified, passed its self-test
  kInvalid,    // a header that fails a check, or marked invalid; SlotStatus::last_error says why
};

constexpr const char* slot_state_text(SlotState s) noexcept {
  switch (s) {
    case SlotState::kEmpty: return "empty";
    case SlotState::kValid: return "valid";
    case SlotState::kTried: return "tried";
    case SlotState::kConfirmed: return "confirmed";
    case SlotState::kInvalid: return "invalid";
  }
  return "unknown";
}

// The states in which the slot holds an image that may run.
constexpr bool holds_usable_image(SlotState s) noexcept {
  return s == SlotState::kValid || s == SlotState::kTried || s == SlotState::kConfirmed;
}

struct SlotStatus {
  SlotState state = SlotState::kEmpty;
  std::uint32_t sequence = 0;          // the header's, when it decodes; else 0
  UpdateError last_error = UpdateError::kOk;  // why the slot is not usable, or the last update into it failed
};

enum class ModelSource : std::uint8_t { kFactory, kSlotA, kSlotB };

constexpr const char* model_source_text(ModelSource s) noexcept {
  switch (s) {
    case ModelSource::kFactory: return "factory";
    case ModelSource::kSlotA: return "slot A";
    case ModelSource::kSlotB: return "slot B";
  }
  return "unknown";
}

// What boot() chose.
struct BootChoice {
  ModelSource source = ModelSource::kFactory;  // kFactory: the compiled-in model
  std::uint32_t sequence = 0;                  // the image's; 0 for the factory model
  std::span<const std::uint8_t> payload{};     // the verified payload in the mapped flash view; empty for factory
  bool trial_this_boot = false;                // the image ran its self-test in this boot (and passed)
};

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_STATUS_H_
