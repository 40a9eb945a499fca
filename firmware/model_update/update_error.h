// Why an image, an update or a slot was refused: one value per cause.
// Returned by ModelSlots (model_slots.h) and kept in each slot's status
// (the reason the slot is not usable, or why the last update into it
// failed), so the USB/link layer can report it.
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_UPDATE_ERROR_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_UPDATE_ERROR_H_

#include <cstdint>

namespace hadynet::model_update {

enum class UpdateError : std::uint8_t {
  kOk = 0,
  // What the header alone shows (begin_update(), and every boot's slot check).
  kMalformedHeader,        // not 256 bytes, wrong magic/version/header size, unknown flags, reserved bytes, sequence 0
  kContractMismatch,       // model contract version is not this firmware's
  kNumericMismatch,        // q15/f32 is not this firmware's
  kShapeMismatch,          // shape id is not this firmware's model's
  kImageTooLarge,          // header + payload do not fit a slot
  kPayloadLengthMismatch,  // payload length is not this firmware's model's
  kSignedByOtherKey,       // the header's public key is not the device's trusted key
  kBadSignature,           // Ed25519 signature over header bytes [0, 192) does not verify
  kNotNewer,               // sequence <= the highest valid slot's, and downgrade not allowed by the signer
  // The payload stream (append_update(), finish_update()).
  kNoUpdateInProgress,     // append/finish without a begin accepted (or after an update ended)
  kTooManyBytes,           // more payload bytes than the header's length
  kTruncated,              // fewer payload bytes than the header's length at finish
  kPayloadHashMismatch,    // SHA-256 of the payload is not the header's (stream, or a slot at boot)
  kReadBackMismatch,       // what the flash reads back differs from what was written
  kFlashError,             // the flash reported an error (ModelSlots::last_flash_status() says which)
  // Slots and the trial.
  kMarkedInvalid,          // the slot's "invalid" flag is set
  kTrialNotConfirmed,      // tried on an earlier boot and never confirmed (crash or power loss in its trial)
  kSelfTestFailed,         // the self-test failed on this boot
  kNotBooted,              // an update before boot() chose what runs
  kBadSlotLayout,          // the slots are not equal, sector-aligned, disjoint, mapped, or too small for the model
};

// A short English description, never null.
const char* update_error_text(UpdateError e) noexcept;

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_UPDATE_ERROR_H_
