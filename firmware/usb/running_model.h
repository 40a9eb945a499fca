// Which model the firmware runs, as the host sees it: the configuration's
// name (iConfiguration, string 10; `hadynet devices` and `lsusb -v` show
// it) is
//
//   "fw <firmware version> model <hash, 16 hex digits> (<source>)"
//
// with <source> "factory" (the compiled-in model) or "slot A, sequence N" /
// "slot B, sequence N" (a signed image the boot rule chose,
// firmware/model_update/model_slots.h), and the hash the running model's:
// M::kModelHash for the factory model, the slot header's model_hash for an
// image. The model runs until the next reset, so the string is made once,
// when the USB device is built (after the boot rule ran).
#ifndef HADYNET_FIRMWARE_USB_RUNNING_MODEL_H_
#define HADYNET_FIRMWARE_USB_RUNNING_MODEL_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/model_update/model_slots.h"
#include "firmware/model_update/slot_status.h"
#include "firmware/app/text.h"

namespace hadynet::usb {

inline constexpr std::size_t kMaxFirmwareVersionChars = 24;
// "fw " + version + " model " + 16 digits + " (slot A, sequence 4294967295)".
inline constexpr std::size_t kMaxVersionStringChars = 3 + kMaxFirmwareVersionChars + 7 + 16 + 30;

struct RunningModel {
  std::uint64_t model_hash = 0;
  model_update::ModelSource source = model_update::ModelSource::kFactory;
  std::uint32_t sequence = 0;  // the image's; 0 for the factory model
};

// The model `slots` booted (null, or not booted: the factory model, whose
// hash is `compiled_model_hash`).
inline RunningModel running_model(const model_update::ModelSlots* slots, std::uint64_t compiled_model_hash) noexcept {
  RunningModel m{compiled_model_hash, model_update::ModelSource::kFactory, 0};
  if (slots == nullptr || !slots->booted()) return m;
  const model_update::BootChoice& choice = slots->choice();
  if (choice.source == model_update::ModelSource::kFactory) return m;
  const model_update::SlotId slot =
      choice.source == model_update::ModelSource::kSlotA ? model_update::SlotId::kA : model_update::SlotId::kB;
  m.source = choice.source;
  m.sequence = choice.sequence;
  m.model_hash = slots->slot_header(slot).model_hash;
  return m;
}

// The configuration's name (above) into `out`, NUL-terminated; the version
// is cut at kMaxFirmwareVersionChars characters.
inline void version_string(const char* firmware_version, const RunningModel& model,
                           app::Text<kMaxVersionStringChars>& out) noexcept {
  out.clear();
  out << "fw ";
  for (std::size_t i = 0; firmware_version != nullptr && firmware_version[i] != '\0' && i < kMaxFirmwareVersionChars;
       ++i) {
    out << firmware_version[i];
  }
  (out << " model ").hex(model.model_hash, 16) << " (";
  out << model_update::model_source_text(model.source);
  if (model.source != model_update::ModelSource::kFactory) out << ", sequence " << model.sequence;
  out << ")";
}

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_RUNNING_MODEL_H_
