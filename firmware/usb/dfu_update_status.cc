#include "firmware/usb/dfu_update_status.h"

namespace hadynet::usb {

namespace mu = model_update;

dfu::Status dfu_status_of(mu::UpdateError error, flash::FlashStatus flash_status, bool in_erase) noexcept {
  switch (error) {
    case mu::UpdateError::kOk:
      return dfu::Status::kOk;
    case mu::UpdateError::kContractMismatch:
    case mu::UpdateError::kNumericMismatch:
    case mu::UpdateError::kShapeMismatch:
    case mu::UpdateError::kPayloadLengthMismatch:
    case mu::UpdateError::kBadSlotLayout:
    case mu::UpdateError::kNotBooted:
      return dfu::Status::kErrTarget;
    case mu::UpdateError::kMalformedHeader:
    case mu::UpdateError::kSignedByOtherKey:
    case mu::UpdateError::kBadSignature:
    case mu::UpdateError::kNotNewer:
    case mu::UpdateError::kPayloadHashMismatch:
      return dfu::Status::kErrFile;
    case mu::UpdateError::kImageTooLarge:
    case mu::UpdateError::kTooManyBytes:
      return dfu::Status::kErrAddress;
    case mu::UpdateError::kTruncated:
      return dfu::Status::kErrNotDone;
    case mu::UpdateError::kReadBackMismatch:
    case mu::UpdateError::kMarkedInvalid:
    case mu::UpdateError::kTrialNotConfirmed:
    case mu::UpdateError::kSelfTestFailed:
      return dfu::Status::kErrVerify;
    case mu::UpdateError::kFlashError:
      switch (flash_status) {
        case flash::FlashStatus::kNotErased:
          return dfu::Status::kErrCheckErased;
        case flash::FlashStatus::kMisaligned:
        case flash::FlashStatus::kCrossesSector:
          return dfu::Status::kErrProg;
        case flash::FlashStatus::kOutOfRange:
          return dfu::Status::kErrAddress;
        case flash::FlashStatus::kWriteError:
        case flash::FlashStatus::kPowerLoss:
        case flash::FlashStatus::kOk:
          return in_erase ? dfu::Status::kErrErase : dfu::Status::kErrWrite;
      }
      return dfu::Status::kErrWrite;
    case mu::UpdateError::kNoUpdateInProgress:
      return dfu::Status::kErrUnknown;
  }
  return dfu::Status::kErrUnknown;
}

const char* flash_status_text(flash::FlashStatus s) noexcept {
  switch (s) {
    case flash::FlashStatus::kOk: return "no error";
    case flash::FlashStatus::kOutOfRange: return "out of range";
    case flash::FlashStatus::kMisaligned: return "misaligned program";
    case flash::FlashStatus::kCrossesSector: return "program crosses a sector";
    case flash::FlashStatus::kNotErased: return "programming over cells not erased";
    case flash::FlashStatus::kWriteError: return "write error";
    case flash::FlashStatus::kPowerLoss: return "power loss";
  }
  return "unknown flash status";
}

void describe_update_error(mu::UpdateError error, const mu::ModelSlots& slots, std::uint32_t image_sequence,
                           bool in_erase, DfuStatusText& out) noexcept {
  out.clear();
  out << mu::update_error_text(error);
  if (error == mu::UpdateError::kNotNewer) {
    // The newest usable image is what the sequence rule compared with.
    std::uint32_t newest = 0;
    const char* where = "";
    for (const mu::SlotId s : {mu::SlotId::kA, mu::SlotId::kB}) {
      const mu::SlotStatus& st = slots.slot_status(s);
      if (mu::holds_usable_image(st.state) && st.sequence > newest) {
        newest = st.sequence;
        where = s == mu::SlotId::kA ? "slot A" : "slot B";
      }
    }
    out << ": image " << image_sequence << ", newest installed " << newest;
    out << " (" << where << ")";
  } else if (error == mu::UpdateError::kFlashError) {
    out << ": " << (flash_status_text(slots.last_flash_status()));
    out << (in_erase ? " while erasing" : " while programming");
    out << (slots.update_target() == mu::SlotId::kA ? " slot A" : " slot B");
  }
}

}  // namespace hadynet::usb
