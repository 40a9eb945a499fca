// ModelSlots' streaming update: begin / append / finish / abort
// (model_slots.h states the rules).
#include "firmware/model_update/model_slots.h"

#include "firmware/model_update/image_check.h"
#include "firmware/model_update/trial_flags.h"

namespace hadynet::model_update {

UpdateError ModelSlots::record(UpdateError e) noexcept {
  last_update_error_ = e;
  return e;
}

SlotId ModelSlots::next_update_target() const noexcept {
  if (choice_.source == ModelSource::kSlotA) return SlotId::kB;
  if (choice_.source == ModelSource::kSlotB) return SlotId::kA;
  // The factory model runs: overwrite what is least worth keeping.
  const auto rank = [this](SlotId s) {
    const SlotStatus& st = status_[slot_index(s)];
    return holds_usable_image(st.state) ? st.sequence : 0u;
  };
  return rank(SlotId::kB) < rank(SlotId::kA) ? SlotId::kB : SlotId::kA;
}

UpdateError ModelSlots::end_failed_update(UpdateError e) noexcept {
  if (stream_.flash_status() != flash::FlashStatus::kOk) last_flash_status_ = stream_.flash_status();
  stream_.abandon();
  if (stream_.touched_flash()) {
    inspect(target_);
    status_[slot_index(target_)].last_error = e;
  }
  return record(e);
}

UpdateError ModelSlots::begin_update(std::span<const std::uint8_t> header) noexcept {
  if (layout_error_ != UpdateError::kOk) return record(layout_error_);
  if (!booted_) return record(UpdateError::kNotBooted);
  if (stream_.active()) abort_update();
  if (header.size() != kImageHeaderSize) return record(UpdateError::kMalformedHeader);
  const std::span<const std::uint8_t, kImageHeaderSize> bytes = header.first<kImageHeaderSize>();
  ModelImageHeader decoded;
  const UpdateError checked =
      check_image_header(bytes, context_.identity, context_.trusted_key, slots_[0].size, decoded);
  if (checked != UpdateError::kOk) return record(checked);
  const bool downgrade = decoded.sequence <= highest_usable_sequence();
  if (downgrade && !decoded.downgrade_allowed) return record(UpdateError::kNotNewer);

  target_ = next_update_target();
  forced_downgrade_ = downgrade;
  flash_.reset_counters();
  update_counters_ = {};
  const UpdateError started = stream_.begin(flash_, slots_[slot_index(target_)], bytes, decoded);
  if (started != UpdateError::kOk) return end_failed_update(started);
  return record(UpdateError::kOk);
}

UpdateError ModelSlots::append_update(std::span<const std::uint8_t> payload_bytes) noexcept {
  if (!stream_.active()) return record(UpdateError::kNoUpdateInProgress);
  const UpdateError e = stream_.append(payload_bytes);
  update_counters_ = flash_.counters();
  if (stream_.touched_flash()) {
    // The first append erased (or began to erase) the target's header.
    status_[slot_index(target_)] = SlotStatus{};
  }
  if (e != UpdateError::kOk) return end_failed_update(e);
  return record(UpdateError::kOk);
}

UpdateError ModelSlots::mark_older_slot_invalid() noexcept {
  const SlotId other = other_slot(target_);
  SlotStatus& status = status_[slot_index(other)];
  const std::uint32_t sequence = status_[slot_index(target_)].sequence;
  if (!holds_usable_image(status.state) || status.sequence < sequence) return UpdateError::kOk;
  const flash::FlashStatus s = set_trial_flag(flash_, slots_[slot_index(other)], TrialFlag::kInvalid);
  if (s != flash::FlashStatus::kOk) {
    last_flash_status_ = s;
    return UpdateError::kFlashError;  // the old image keeps winning: the downgrade did not happen
  }
  status.state = SlotState::kInvalid;
  status.last_error = UpdateError::kMarkedInvalid;
  return UpdateError::kOk;
}

UpdateError ModelSlots::finish_update() noexcept {
  if (!stream_.active()) return record(UpdateError::kNoUpdateInProgress);
  const UpdateError e = stream_.finish();
  update_counters_ = flash_.counters();
  if (e != UpdateError::kOk) return end_failed_update(e);
  // Check the slot as the next boot will (signature and hash over what the
  // flash now holds).
  inspect(target_);
  const SlotStatus& written = status_[slot_index(target_)];
  if (written.state != SlotState::kValid) {
    return record(written.last_error != UpdateError::kOk ? written.last_error : UpdateError::kReadBackMismatch);
  }
  UpdateError result = UpdateError::kOk;
  if (forced_downgrade_) result = mark_older_slot_invalid();
  update_counters_ = flash_.counters();
  return record(result);
}

void ModelSlots::abort_update() noexcept {
  if (!stream_.active()) return;
  stream_.abandon();
  if (stream_.touched_flash()) inspect(target_);
}

}  // namespace hadynet::model_update
