// ModelSlots::boot(): the boot rule with trial, confirm and revert
// (model_slots.h states it).
#include "firmware/model_update/model_slots.h"

#include "firmware/model_update/trial_flags.h"

namespace hadynet::model_update {

bool ModelSlots::pick_winner(const std::array<bool, kSlotCount>& excluded, SlotId& winner) const noexcept {
  bool found = false;
  for (const SlotId s : {SlotId::kA, SlotId::kB}) {
    const std::size_t i = slot_index(s);
    if (excluded[i] || !holds_usable_image(status_[i].state)) continue;
    if (!found) {
      winner = s;
      found = true;
      continue;
    }
    const SlotStatus& best = status_[slot_index(winner)];
    const bool newer = status_[i].sequence > best.sequence;
    const bool tie_confirmed = status_[i].sequence == best.sequence && status_[i].state == SlotState::kConfirmed &&
                               best.state != SlotState::kConfirmed;
    if (newer || tie_confirmed) winner = s;
  }
  return found;
}

void ModelSlots::invalidate(SlotId slot, UpdateError why) noexcept {
  const std::size_t i = slot_index(slot);
  const flash::FlashStatus s = set_trial_flag(flash_, slots_[i], TrialFlag::kInvalid);
  if (s != flash::FlashStatus::kOk) last_flash_status_ = s;
  // Invalid for this boot whatever the flash said; a slot whose flag did
  // not stick is tried-but-unconfirmed, so the next boot invalidates it.
  status_[i].state = SlotState::kInvalid;
  status_[i].last_error = why;
}

void ModelSlots::choose(SlotId slot, bool trial_this_boot) noexcept {
  const std::size_t i = slot_index(slot);
  choice_.source = slot == SlotId::kA ? ModelSource::kSlotA : ModelSource::kSlotB;
  choice_.sequence = status_[i].sequence;
  choice_.payload = slot_payload(context_.mapped_flash, slots_[i], headers_[i].payload_length);
  choice_.trial_this_boot = trial_this_boot;
}

BootChoice ModelSlots::boot(SelfTest& self_test) noexcept {
  stream_.abandon();
  booted_ = true;
  choice_ = BootChoice{};
  if (layout_error_ != UpdateError::kOk) return choice_;
  inspect(SlotId::kA);
  inspect(SlotId::kB);

  std::array<bool, kSlotCount> excluded{};
  SlotId winner = SlotId::kA;
  while (pick_winner(excluded, winner)) {
    const std::size_t i = slot_index(winner);
    SlotStatus& status = status_[i];
    if (status.state == SlotState::kConfirmed) {
      choose(winner, false);
      return choice_;
    }
    if (status.state == SlotState::kTried) {
      invalidate(winner, UpdateError::kTrialNotConfirmed);
      excluded[i] = true;
      continue;
    }
    // A first trial: "tried" must be on the flash before the image runs, so
    // a crash during the trial reverts it on the next boot.
    const flash::FlashStatus tried = set_trial_flag(flash_, slots_[i], TrialFlag::kTried);
    if (tried != flash::FlashStatus::kOk) {
      last_flash_status_ = tried;
      status.last_error = UpdateError::kFlashError;
      excluded[i] = true;
      continue;
    }
    status.state = SlotState::kTried;
    const std::span<const std::uint8_t> payload =
        slot_payload(context_.mapped_flash, slots_[i], headers_[i].payload_length);
    if (!self_test.run(payload, headers_[i])) {
      invalidate(winner, UpdateError::kSelfTestFailed);
      excluded[i] = true;
      continue;
    }
    const flash::FlashStatus confirmed = set_trial_flag(flash_, slots_[i], TrialFlag::kConfirmed);
    if (confirmed == flash::FlashStatus::kOk) {
      status.state = SlotState::kConfirmed;
    } else {
      // It passed, so it runs now; unconfirmed on the flash, the next boot reverts it.
      last_flash_status_ = confirmed;
      status.last_error = UpdateError::kFlashError;
    }
    choose(winner, true);
    return choice_;
  }
  return choice_;  // the factory model
}

}  // namespace hadynet::model_update
