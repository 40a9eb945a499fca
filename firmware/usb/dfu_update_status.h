// What the DFU model interface reports when ModelSlots refuses an image or
// an update fails: a DFU 1.1 status code (GETSTATUS bStatus) per
// model_update::UpdateError, and the description the host reads as the
// status string (GETSTATUS iString). docs/usb.md, "Status codes", has the
// table; the choice follows DFU 1.1 §6.1.2's meanings:
//
//   errTARGET   the file is not for this device: contract, numeric, shape or
//               payload length of another firmware; no usable slots
//               (bad slot layout, no boot decision yet)
//   errFILE     the file fails the device's verification: malformed header,
//               signed by another key, bad signature, sequence not newer,
//               payload SHA-256 of the received stream not the header's
//   errADDRESS  the image does not fit a slot; more payload bytes than the
//               header says
//   errNOTDONE  the download ended before the header's payload length
//   errVERIFY   the flash read back differs from what was written, or the
//               written slot fails the boot's slot check
//   errERASE / errWRITE / errCHECK_ERASED / errPROG
//               the flash reported an error (ModelSlots::last_flash_status()):
//               kWriteError or kPowerLoss during an erase / a program,
//               programming over cells not erased, a misaligned or
//               sector-crossing program
//   errUNKNOWN  anything else (an update call out of order: a bug)
#ifndef HADYNET_FIRMWARE_USB_DFU_UPDATE_STATUS_H_
#define HADYNET_FIRMWARE_USB_DFU_UPDATE_STATUS_H_

#include "firmware/flash/flash_device.h"
#include "firmware/model_update/model_slots.h"
#include "firmware/model_update/update_error.h"
#include "firmware/usb/dfu_spec.h"
#include "firmware/app/text.h"

namespace hadynet::usb {

// Characters of the DFU status string (a string descriptor holds at most 126).
inline constexpr std::size_t kDfuStatusTextChars = 126;
using DfuStatusText = app::Text<kDfuStatusTextChars>;

// The status of `error`; `flash_status` is the flash's error behind a
// kFlashError, `in_erase` whether the failing operation was an erase.
dfu::Status dfu_status_of(model_update::UpdateError error, flash::FlashStatus flash_status, bool in_erase) noexcept;

// "flash error: write error" and the like (flash_device.h's statuses).
const char* flash_status_text(flash::FlashStatus s) noexcept;

// The description of a refusal by `slots` (whose last_update_error() is
// `error`): update_error_text(), plus for kNotNewer the sequence numbers
// ("...: image 2, newest installed 3 (slot B)") and for kFlashError what
// the flash said and whether it was erasing.
void describe_update_error(model_update::UpdateError error, const model_update::ModelSlots& slots,
                           std::uint32_t image_sequence, bool in_erase, DfuStatusText& out) noexcept;

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_DFU_UPDATE_STATUS_H_
