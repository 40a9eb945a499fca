#include "firmware/model_update/update_error.h"

namespace hadynet::model_update {

const char* update_error_text(UpdateError e) noexcept {
  switch (e) {
    case UpdateError::kOk: return "ok";
    case UpdateError::kMalformedHeader: return "malformed image header";
    case UpdateError::kContractMismatch: return "model contract version does not match the firmware";
    case UpdateError::kNumericMismatch: return "numeric (q15/f32) does not match the firmware";
    case UpdateError::kShapeMismatch: return "model shape does not match the firmware";
    case UpdateError::kImageTooLarge: return "image larger than a slot";
    case UpdateError::kPayloadLengthMismatch: return "payload length does not match the firmware's model";
    case UpdateError::kSignedByOtherKey: return "signed by another key";
    case UpdateError::kBadSignature: return "signature does not verify";
    case UpdateError::kNotNewer: return "sequence number not newer than the installed image (downgrade)";
    case UpdateError::kNoUpdateInProgress: return "no update in progress";
    case UpdateError::kTooManyBytes: return "more payload bytes than the header says";
    case UpdateError::kTruncated: return "payload shorter than the header says";
    case UpdateError::kPayloadHashMismatch: return "payload SHA-256 does not match the header";
    case UpdateError::kReadBackMismatch: return "flash read-back differs from what was written";
    case UpdateError::kFlashError: return "flash error";
    case UpdateError::kMarkedInvalid: return "slot marked invalid";
    case UpdateError::kTrialNotConfirmed: return "trial never confirmed (reverted)";
    case UpdateError::kSelfTestFailed: return "self-test failed (reverted)";
    case UpdateError::kNotBooted: return "no boot decision yet";
    case UpdateError::kBadSlotLayout: return "bad slot layout";
  }
  return "unknown error";
}

}  // namespace hadynet::model_update
