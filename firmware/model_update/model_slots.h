// The device's two model slots (A and B): which model boots, trial /
// confirm / revert, and streaming a signed image into a slot. MCUboot's
// "direct XIP with revert" idea: images run in place from the slot they
// were written to, the newest valid one wins, and a new image must pass a
// self-test on its first boot or it is reverted. No heap; all state lives
// in this object (place it in static storage).
//
// THE BOOT RULE (boot()):
//   1. Check both slots (slot_inspection.h): usable = header well-formed,
//      identity/size/trusted key/signature pass, payload SHA-256 matches,
//      "invalid" flag not set.
//   2. Among usable slots the highest sequence wins (tie: the confirmed
//      one, then A). None usable: the factory (compiled-in) model.
//   3. Winner confirmed: run it.
//      Winner tried but not confirmed (its trial crashed or lost power):
//      mark it invalid, go to 2 without it.
//      Winner never tried: mark it tried (BEFORE first use; if that write
//      fails it is not used in this boot), run the SelfTest on its payload:
//      pass: mark it confirmed and run it; fail: mark it invalid, go to 2.
//   Each round removes a slot or returns, so boot() ends after at most
//   three rounds, and it never returns an image that was not verified in
//   this boot.
//
// THE UPDATE (begin_update, append_update*, finish_update):
//   begin_update(header) checks what the header alone shows BEFORE
//   anything is erased: check_image_header() (malformed, contract, numeric,
//   shape, too large, payload length, key, signature) and the sequence rule
//   (sequence <= the highest sequence among usable slots: kNotNewer, unless
//   the signer set the downgrade flag). The target is never the slot in use
//   (the one boot() chose); with the factory model in use, the slot that
//   holds no usable image, else the one with the lower sequence (tie: A).
//   append_update() streams the payload into the target from slot offset
//   1024 (its first append erases the target's header and flags);
//   finish_update() checks length, stream hash, read-back hash, then
//   programs the header. The new image is then "valid": the next boot
//   tries it if it has the highest sequence.
//   Forced downgrade (downgrade flag set and sequence <= the highest usable
//   one): after the header is programmed, the other slot is marked invalid
//   when it holds a usable image with a sequence >= the new one, so the new
//   image wins the next boot. Its fallback is then the FACTORY model (the
//   old image is invalid for good); a power cut between the header and that
//   mark leaves the old image winning (the downgrade did not happen).
//   A refused image leaves the slot in use and the boot choice untouched;
//   one refused by begin_update() also leaves the target untouched; one
//   refused later (append/finish: too many bytes, truncation, hash,
//   read-back, flash errors) leaves the target without a header (empty),
//   everything else untouched.
//
// Offsets: slot regions are device offsets (FlashDevice); the mapped view
// covers the device from offset 0 (F405: 0x08000000, 1 MiB; host: the
// simulated flash's contents()).
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_MODEL_SLOTS_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_MODEL_SLOTS_H_

#include <array>
#include <cstdint>
#include <span>

#include "firmware/flash/flash_device.h"
#include "firmware/flash/flash_region_writer.h"
#include "firmware/model_update/counting_flash.h"
#include "firmware/model_update/model_identity.h"
#include "firmware/model_update/model_image.h"
#include "firmware/model_update/self_test.h"
#include "firmware/model_update/slot_inspection.h"
#include "firmware/model_update/slot_status.h"
#include "firmware/model_update/slot_update_stream.h"
#include "firmware/model_update/update_error.h"

namespace hadynet::model_update {

class ModelSlots {
 public:
  // `slot_a`, `slot_b`: equal, sector-aligned, disjoint regions of `flash`,
  // each at least 1024 + identity.payload_length bytes; `mapped_flash`
  // covers the whole device. Otherwise layout_error() is kBadSlotLayout,
  // boot() returns the factory model and updates are refused. The key is
  // copied; `flash` and the mapped view must outlive this object.
  ModelSlots(flash::FlashDevice& flash, const flash::FlashRegion& slot_a, const flash::FlashRegion& slot_b,
             const ModelIdentity& identity, std::span<const std::uint8_t, kPublicKeyBytes> trusted_public_key,
             std::span<const std::uint8_t> mapped_flash) noexcept;
  ModelSlots(const ModelSlots&) = delete;
  ModelSlots& operator=(const ModelSlots&) = delete;

  UpdateError layout_error() const noexcept { return layout_error_; }

  // ---- Boot (once per reset, before the model is used; see the rule above).
  // Writes trial flags; runs `self_test` at most once per slot. Ends an
  // update in progress (its target keeps no header).
  BootChoice boot(SelfTest& self_test) noexcept;
  // The last boot()'s choice (the factory model before any boot()).
  const BootChoice& choice() const noexcept { return choice_; }
  bool booted() const noexcept { return booted_; }

  // ---- Status for the USB/link layer.
  const SlotStatus& slot_status(SlotId slot) const noexcept { return status_[slot_index(slot)]; }
  // The slot's decoded header; meaningful when slot_status(slot).sequence != 0.
  const ModelImageHeader& slot_header(SlotId slot) const noexcept { return headers_[slot_index(slot)]; }
  const flash::FlashRegion& slot_region(SlotId slot) const noexcept { return slots_[slot_index(slot)]; }

  // ---- Update (see above). Each returns kOk or why it refused; after an
  // error the update is over (append/finish answer kNoUpdateInProgress).
  // `header`: exactly the 256 header bytes.
  UpdateError begin_update(std::span<const std::uint8_t> header) noexcept;
  UpdateError append_update(std::span<const std::uint8_t> payload_bytes) noexcept;
  UpdateError finish_update() noexcept;
  // Ends an update in progress without a header (e.g. the host aborted).
  void abort_update() noexcept;

  bool update_in_progress() const noexcept { return stream_.active(); }
  // The slot the next begin_update() would write (the rule above): never the
  // slot in use; with the factory model in use, the slot holding no usable
  // image, else the one with the lower sequence (tie: A).
  SlotId next_update_target() const noexcept;
  // The slot the current (or last accepted) update writes.
  SlotId update_target() const noexcept { return target_; }
  // Payload bytes accepted by the current (or last) update.
  std::uint32_t update_received() const noexcept { return stream_.received(); }
  // The result of the last begin/append/finish call.
  UpdateError last_update_error() const noexcept { return last_update_error_; }
  // The flash status behind the last kFlashError (of an update or a boot flag write).
  flash::FlashStatus last_flash_status() const noexcept { return last_flash_status_; }
  // Erases and programming of the current (or last) update, from
  // begin_update() on: the payload, its padding, the header, and a forced
  // downgrade's invalid flag.
  const FlashCounters& update_counters() const noexcept { return update_counters_; }

 private:
  void inspect(SlotId slot) noexcept;
  bool pick_winner(const std::array<bool, kSlotCount>& excluded, SlotId& winner) const noexcept;
  void invalidate(SlotId slot, UpdateError why) noexcept;
  void choose(SlotId slot, bool trial_this_boot) noexcept;
  std::uint32_t highest_usable_sequence() const noexcept;
  UpdateError record(UpdateError e) noexcept;
  UpdateError end_failed_update(UpdateError e) noexcept;
  UpdateError mark_older_slot_invalid() noexcept;

  CountingFlashDevice flash_;
  std::array<flash::FlashRegion, kSlotCount> slots_;
  SlotCheckContext context_;
  UpdateError layout_error_ = UpdateError::kOk;

  std::array<SlotStatus, kSlotCount> status_{};
  std::array<ModelImageHeader, kSlotCount> headers_{};
  BootChoice choice_{};
  bool booted_ = false;

  SlotUpdateStream stream_;
  SlotId target_ = SlotId::kA;
  bool forced_downgrade_ = false;
  UpdateError last_update_error_ = UpdateError::kOk;
  flash::FlashStatus last_flash_status_ = flash::FlashStatus::kOk;
  FlashCounters update_counters_{};
};

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_MODEL_SLOTS_H_
