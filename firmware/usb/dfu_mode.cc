#include "firmware/usb/dfu_mode.h"

#include "firmware/core/little_endian.h"
#include "firmware/model_update/slot_status.h"
#include "firmware/usb/dfu_update_timing.h"
#include "firmware/usb/slot_image_file.h"

namespace hadynet::usb {

namespace {

namespace mu = model_update;

constexpr std::uint32_t kMaxPollMs = 0xFFFFFF;  // bwPollTimeout is 24 bits
constexpr const char* kNoSlotsText = "this device has no model slots: it takes no model images";
constexpr const char* kReadErrorText = "flash read error during the upload";

bool is_class_request_to(const SetupPacket& s, std::uint8_t interface) noexcept {
  return s.kind() == RequestKind::kClass && s.recipient() == Recipient::kInterface && s.index == interface;
}

const char* slot_name(mu::SlotId s) noexcept { return s == mu::SlotId::kA ? "slot A" : "slot B"; }

}  // namespace

DfuMode::DfuMode(const ModelSlotsAccess& model, std::uint8_t interface, std::uint8_t status_string) noexcept
    : slots_(model.flash != nullptr ? model.slots : nullptr),
      flash_(model.slots != nullptr ? model.flash : nullptr),
      interface_(interface),
      status_string_(status_string) {}

void DfuMode::end_update() noexcept {
  if (slots_ != nullptr && slots_->update_in_progress()) slots_->abort_update();
}

ControlReply DfuMode::refuse() noexcept {
  if (state_ != dfu::State::kError) {
    const auto state = static_cast<std::uint32_t>(state_);
    fail(dfu::Status::kErrStalledPacket, "request not allowed in this DFU state");
    text_ << " (" << state << ")";
  }
  block_pending_ = false;
  manifest_pending_ = false;
  return ControlReply::stall();
}

void DfuMode::fail(dfu::Status status, const char* text) noexcept {
  end_update();
  state_ = dfu::State::kError;
  status_ = status;
  update_error_ = mu::UpdateError::kOk;
  block_pending_ = false;
  manifest_pending_ = false;
  text_.clear();
  text_ << text;
}

void DfuMode::fail_update(mu::UpdateError error, bool in_erase) noexcept {
  const dfu::Status status = dfu_status_of(error, slots_->last_flash_status(), in_erase);
  fail(status, "");
  update_error_ = error;
  describe_update_error(error, *slots_, header_sequence(), in_erase, text_);
}

void DfuMode::reset_to_idle() noexcept {
  end_update();
  state_ = dfu::State::kIdle;
  status_ = dfu::Status::kOk;
  update_error_ = mu::UpdateError::kOk;
  text_.clear();
  block_pending_ = false;
  manifest_pending_ = false;
  block_size_ = 0;
  header_received_ = 0;
  upload_offset_ = 0;
  upload_size_ = 0;
}

ControlReply DfuMode::control_setup(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept {
  if (!is_class_request_to(s, interface_)) return ControlReply::stall();
  const bool busy = state_ == dfu::State::kDnBusy || state_ == dfu::State::kManifest;
  if (busy && s.request != dfu::kGetStatus) return refuse();
  switch (s.request) {
    case dfu::kDnload:
      if (s.is_in() || s.length > kDfuTransferSize) return refuse();
      if (state_ == dfu::State::kIdle) {
        if (s.length == 0) return refuse();
        return start_download(s);
      }
      if (state_ == dfu::State::kDnloadIdle) {
        if (s.length == 0) {  // end of the file
          state_ = dfu::State::kManifestSync;
          manifest_pending_ = true;
          return ControlReply::ack();
        }
        return ControlReply::data_out();
      }
      return refuse();
    case dfu::kUpload:
      if (!s.is_in() || s.length == 0 || s.length > kDfuTransferSize) return refuse();
      return upload(s, buffer);
    case dfu::kGetStatus:
      if (!s.is_in() || s.value != 0 || s.length != dfu::kStatusSize) return refuse();
      return get_status(buffer);
    case dfu::kClrStatus:
      if (s.is_in() || s.length != 0 || state_ != dfu::State::kError) return refuse();
      reset_to_idle();
      return ControlReply::ack();
    case dfu::kGetState:
      if (!s.is_in() || s.value != 0 || s.length != 1) return refuse();
      buffer[0] = static_cast<std::uint8_t>(state_);
      return ControlReply::data_in(1);
    case dfu::kAbort:
      if (s.is_in() || s.length != 0) return refuse();
      switch (state_) {
        case dfu::State::kIdle:
        case dfu::State::kDnloadSync:
        case dfu::State::kDnloadIdle:
        case dfu::State::kManifestSync:
        case dfu::State::kUploadIdle:
          reset_to_idle();
          return ControlReply::ack();
        default:
          return refuse();
      }
    default:  // DFU_DETACH (a runtime request) and anything unknown
      return refuse();
  }
}

ControlReply DfuMode::start_download(const SetupPacket& s) noexcept {
  if (slots_ == nullptr) {
    fail(dfu::Status::kErrTarget, kNoSlotsText);
    return ControlReply::stall();
  }
  if (alternate_ != kDfuAltModelUpdate) {
    fail(dfu::Status::kErrWrite, "alternate 1 (the running model) is read only: send images to alternate 0");
    return ControlReply::stall();
  }
  text_.clear();
  update_error_ = mu::UpdateError::kOk;
  header_received_ = 0;
  next_block_ = s.value;  // the first block's number is the host's choice
  return ControlReply::data_out();
}

bool DfuMode::control_out(const SetupPacket& s, std::span<const std::uint8_t> data) noexcept {
  if (s.request != dfu::kDnload || (state_ != dfu::State::kIdle && state_ != dfu::State::kDnloadIdle)) return false;
  if (data.empty() || data.size() > sizeof(block_)) return false;
  if (s.value != next_block_) {
    fail(dfu::Status::kErrAddress, "DNLOAD block number out of sequence");  // seen in the next GETSTATUS
    return true;
  }
  for (std::size_t i = 0; i < data.size(); ++i) block_[i] = data[i];
  block_size_ = data.size();
  block_pending_ = true;
  ++next_block_;
  state_ = dfu::State::kDnloadSync;
  return true;
}

std::uint32_t DfuMode::block_work_ms() const noexcept {
  const std::size_t header_left = mu::kImageHeaderSize - header_received_;
  const std::size_t header_part = block_size_ < header_left ? block_size_ : header_left;
  const std::size_t payload_part = block_size_ - header_part;
  std::uint64_t ms = 0;
  if (header_part > 0 && header_part == header_left) ms += kDfuHeaderCheckMs;
  if (payload_part > 0) {
    if (slots_->update_in_progress()) {
      ms += payload_append_ms(*flash_, slots_->slot_region(slots_->update_target()), slots_->update_received(),
                              payload_part);
    } else {
      // begin_update() in the same service() picks the target by this rule.
      ms += payload_append_ms(*flash_, slots_->slot_region(slots_->next_update_target()), 0, payload_part);
    }
  }
  return ms > kMaxPollMs ? kMaxPollMs : static_cast<std::uint32_t>(ms);
}

ControlReply DfuMode::get_status(std::span<std::uint8_t> buffer) noexcept {
  switch (state_) {
    case dfu::State::kDnloadSync:
      if (block_pending_) {
        state_ = dfu::State::kDnBusy;
        poll_ms_ = block_work_ms();
      } else {
        state_ = dfu::State::kDnloadIdle;
        poll_ms_ = 0;
      }
      break;
    case dfu::State::kDnBusy:
      poll_ms_ = block_work_ms();
      break;
    case dfu::State::kManifestSync:
      if (manifest_pending_) {
        state_ = dfu::State::kManifest;  // 7, never MANIFEST-WAIT-RESET
        poll_ms_ = kDfuManifestMs;
      } else {
        state_ = dfu::State::kIdle;  // manifestation tolerant: back to dfuIDLE
        poll_ms_ = 0;
      }
      break;
    case dfu::State::kManifest:
      poll_ms_ = kDfuManifestMs;
      break;
    default:
      poll_ms_ = 0;
      break;
  }
  if (poll_ms_ > kMaxPollMs) poll_ms_ = kMaxPollMs;
  buffer[0] = static_cast<std::uint8_t>(status_);
  buffer[1] = static_cast<std::uint8_t>(poll_ms_);
  buffer[2] = static_cast<std::uint8_t>(poll_ms_ >> 8);
  buffer[3] = static_cast<std::uint8_t>(poll_ms_ >> 16);
  buffer[4] = static_cast<std::uint8_t>(state_);
  buffer[5] = text_.empty() ? 0 : status_string_;  // iString
  return ControlReply::data_in(dfu::kStatusSize);
}

bool DfuMode::upload_slot(flash::FlashRegion& region) const noexcept {
  if (slots_->layout_error() != mu::UpdateError::kOk) return false;
  mu::SlotId slot = mu::SlotId::kA;
  if (alternate_ == kDfuAltModelUpdate) {
    slot = wrote_a_slot_ ? written_slot_ : slots_->next_update_target();
  } else {
    const mu::ModelSource running = slots_->choice().source;
    if (running == mu::ModelSource::kFactory) return false;  // no slot in use
    slot = running == mu::ModelSource::kSlotA ? mu::SlotId::kA : mu::SlotId::kB;
  }
  region = slots_->slot_region(slot);
  return true;
}

bool DfuMode::start_upload() noexcept {
  if (slots_ == nullptr) {
    fail(dfu::Status::kErrTarget, kNoSlotsText);
    return false;
  }
  upload_offset_ = 0;
  upload_size_ = 0;
  upload_region_ = {};
  flash::FlashRegion region;
  if (!upload_slot(region)) return true;  // nothing to read: a file of 0 bytes
  if (slot_image_file_size(*flash_, region, upload_size_) != flash::FlashStatus::kOk) {
    fail(dfu::Status::kErrUnknown, kReadErrorText);
    return false;
  }
  upload_region_ = region;
  return true;
}

ControlReply DfuMode::upload(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept {
  if (state_ == dfu::State::kIdle) {
    if (!start_upload()) return ControlReply::stall();
    upload_next_block_ = s.value;
  } else if (state_ != dfu::State::kUploadIdle) {
    return refuse();
  }
  if (s.value != upload_next_block_) {
    fail(dfu::Status::kErrAddress, "UPLOAD block number out of sequence");
    return ControlReply::stall();
  }
  const std::uint32_t left = upload_size_ - upload_offset_;
  const std::uint32_t n = s.length < left ? s.length : left;
  if (n > 0 && read_slot_image_file(*flash_, upload_region_, upload_size_, upload_offset_, buffer.first(n)) !=
                   flash::FlashStatus::kOk) {
    fail(dfu::Status::kErrUnknown, kReadErrorText);
    return ControlReply::stall();
  }
  upload_offset_ += n;
  ++upload_next_block_;
  state_ = n < s.length ? dfu::State::kIdle : dfu::State::kUploadIdle;  // a short block ends the upload
  return ControlReply::data_in(n);
}

void DfuMode::service() noexcept {
  if (state_ == dfu::State::kDnBusy && block_pending_) {
    process_block();
  } else if (state_ == dfu::State::kManifest && manifest_pending_) {
    manifest();
  }
}

void DfuMode::process_block() noexcept {
  block_pending_ = false;
  std::span<const std::uint8_t> data(block_, block_size_);
  if (header_received_ < mu::kImageHeaderSize) {
    const std::size_t left = mu::kImageHeaderSize - header_received_;
    const std::size_t n = data.size() < left ? data.size() : left;
    for (std::size_t i = 0; i < n; ++i) header_[header_received_ + i] = data[i];
    header_received_ += n;
    data = data.subspan(n);
    if (header_received_ == mu::kImageHeaderSize) {
      const mu::UpdateError e = slots_->begin_update(std::span<const std::uint8_t>(header_));
      if (e != mu::UpdateError::kOk) {
        fail_update(e, false);
        return;
      }
      wrote_a_slot_ = true;
      written_slot_ = slots_->update_target();
    }
  }
  if (!data.empty() && !append(data)) return;
  state_ = dfu::State::kDnloadSync;
}

bool DfuMode::append(std::span<const std::uint8_t> payload) noexcept {
  const std::uint32_t written = slots_->update_received();
  const mu::FlashCounters before = slots_->update_counters();
  const mu::UpdateError e = slots_->append_update(payload);
  if (e == mu::UpdateError::kOk) return true;
  bool in_erase = false;
  if (e == mu::UpdateError::kFlashError) {
    const mu::FlashCounters& after = slots_->update_counters();
    mu::FlashCounters done;
    done.erases = after.erases - before.erases;
    done.program_operations = after.program_operations - before.program_operations;
    done.programmed_bytes = after.programmed_bytes - before.programmed_bytes;
    in_erase = append_failed_in_erase(*flash_, slots_->slot_region(slots_->update_target()), written,
                                      payload.size(), done);
  }
  fail_update(e, in_erase);
  return false;
}

void DfuMode::manifest() noexcept {
  manifest_pending_ = false;
  if (header_received_ < mu::kImageHeaderSize) {
    fail(dfu::Status::kErrNotDone, "the file ends inside the 256-byte image header");
    return;
  }
  // Stream flash errors here are programs (the padding, the header): the
  // sectors were erased by the payload.
  const mu::UpdateError e = slots_->finish_update();
  if (e != mu::UpdateError::kOk) {
    fail_update(e, false);
    return;
  }
  ++images_written_;
  text_.clear();
  text_ << "image sequence " << header_sequence() << " written to ";
  text_ << (slot_name(slots_->update_target())) << ": the boot rule tries it at the next reset";
  state_ = dfu::State::kManifestSync;
}

std::uint32_t DfuMode::header_sequence() const noexcept {
  if (header_received_ < mu::kImageHeaderSize) return 0;
  return get_le32(header_ + mu::header_offset::kSequence);
}

bool DfuMode::configure(DeviceController&) noexcept {
  reset_to_idle();
  alternate_ = kDfuAltModelUpdate;
  return true;
}

void DfuMode::deconfigure() noexcept {
  reset_to_idle();
  alternate_ = kDfuAltModelUpdate;
}

bool DfuMode::set_alternate(std::uint8_t interface, std::uint8_t alternate) noexcept {
  if (interface != interface_ || alternate >= kDfuAlternateCount) return false;
  if (state_ == dfu::State::kDnBusy || state_ == dfu::State::kManifest) return false;
  alternate_ = alternate;
  reset_to_idle();
  return true;
}

std::uint8_t DfuMode::alternate(std::uint8_t) const noexcept { return alternate_; }

}  // namespace hadynet::usb
