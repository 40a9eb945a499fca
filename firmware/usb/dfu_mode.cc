#include "firmware/usb/dfu_mode.h"

#include "firmware/link/crc32.h"

namespace hadynet::usb {

namespace {

constexpr std::uint32_t kMaxPollMs = 0xFFFFFF;  // bwPollTimeout is 24 bits

bool is_class_request_to(const SetupPacket& s, std::uint8_t interface) noexcept {
  return s.kind() == RequestKind::kClass && s.recipient() == Recipient::kInterface && s.index == interface;
}

}  // namespace

bool DfuMode::target_usable() const noexcept {
  return alternate_ < targets_.size() &&
         flash::region_is_sector_aligned(flash_.sectors(), targets_[alternate_].region) &&
         targets_[alternate_].region.size > kDfuImageHeaderSize;
}

ControlReply DfuMode::refuse() noexcept {
  if (state_ != dfu::State::kError) {
    status_ = dfu::Status::kErrStalledPacket;
    state_ = dfu::State::kError;
  }
  block_pending_ = false;
  manifest_pending_ = false;
  return ControlReply::stall();
}

void DfuMode::fail(dfu::Status status) noexcept {
  state_ = dfu::State::kError;
  status_ = status;
  block_pending_ = false;
  manifest_pending_ = false;
}

void DfuMode::reset_to_idle() noexcept {
  state_ = dfu::State::kIdle;
  status_ = dfu::Status::kOk;
  block_pending_ = false;
  manifest_pending_ = false;
  block_size_ = 0;
  received_ = 0;
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
        if (!target_usable()) {
          fail(dfu::Status::kErrTarget);
          return ControlReply::stall();
        }
        if (!targets_[alternate_].can_download) {
          fail(dfu::Status::kErrWrite);
          return ControlReply::stall();
        }
        if (!writer_.begin(flash_, targets_[alternate_].region, kDfuImageHeaderSize).ok()) {
          fail(dfu::Status::kErrTarget);
          return ControlReply::stall();
        }
        received_ = 0;
        stream_crc_ = link::crc32_begin();
        next_block_ = s.value;  // the first block's number is the host's choice
        return ControlReply::data_out();
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

bool DfuMode::control_out(const SetupPacket& s, std::span<const std::uint8_t> data) noexcept {
  if (s.request != dfu::kDnload || (state_ != dfu::State::kIdle && state_ != dfu::State::kDnloadIdle)) return false;
  if (data.empty() || data.size() > sizeof(block_)) return false;
  if (s.value != next_block_) {
    fail(dfu::Status::kErrAddress);  // the host sees it in the next GETSTATUS
    return true;
  }
  for (std::size_t i = 0; i < data.size(); ++i) block_[i] = data[i];
  block_size_ = data.size();
  block_pending_ = true;
  ++next_block_;
  state_ = dfu::State::kDnloadSync;
  return true;
}

ControlReply DfuMode::get_status(std::span<std::uint8_t> buffer) noexcept {
  switch (state_) {
    case dfu::State::kDnloadSync:
      if (block_pending_) {
        state_ = dfu::State::kDnBusy;
        poll_ms_ = writer_.estimate_append_ms(block_size_);
      } else {
        state_ = dfu::State::kDnloadIdle;
        poll_ms_ = 0;
      }
      break;
    case dfu::State::kDnBusy:
      poll_ms_ = writer_.estimate_append_ms(block_size_);
      break;
    case dfu::State::kManifestSync:
      if (manifest_pending_) {
        state_ = dfu::State::kManifest;  // 7, never MANIFEST-WAIT-RESET
        poll_ms_ = kDfuManifestPollMs;
      } else {
        state_ = dfu::State::kIdle;  // manifestation tolerant: back to dfuIDLE
        poll_ms_ = 0;
      }
      break;
    case dfu::State::kManifest:
      poll_ms_ = kDfuManifestPollMs;
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
  buffer[5] = 0;  // iString
  return ControlReply::data_in(dfu::kStatusSize);
}

ControlReply DfuMode::upload(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept {
  if (state_ == dfu::State::kIdle) {
    if (!target_usable()) {
      fail(dfu::Status::kErrTarget);
      return ControlReply::stall();
    }
    if (!targets_[alternate_].can_upload) return refuse();
    const flash::FlashRegion& region = targets_[alternate_].region;
    std::uint8_t bytes[kDfuImageHeaderSize] = {};
    if (flash_.read(region.offset, bytes) != flash::FlashStatus::kOk) {
      fail(dfu::Status::kErrUnknown);
      return ControlReply::stall();
    }
    const DfuImageHeader h = decode_dfu_image_header(bytes);
    // Only a complete image is readable: its header is written last.
    upload_size_ = h.well_formed() && h.length <= region.size - kDfuImageHeaderSize
                       ? static_cast<std::uint32_t>(kDfuImageHeaderSize) + h.length
                       : 0;
    upload_offset_ = 0;
    upload_next_block_ = s.value;
  } else if (state_ != dfu::State::kUploadIdle) {
    return refuse();
  }
  if (s.value != upload_next_block_) {
    fail(dfu::Status::kErrAddress);
    return ControlReply::stall();
  }
  const std::uint32_t left = upload_size_ - upload_offset_;
  const std::uint32_t n = s.length < left ? s.length : left;
  if (n > 0 && flash_.read(targets_[alternate_].region.offset + upload_offset_, buffer.first(n)) !=
                   flash::FlashStatus::kOk) {
    fail(dfu::Status::kErrUnknown);
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
  while (received_ < kDfuImageHeaderSize && !data.empty()) {
    header_bytes_[received_++] = data.front();
    data = data.subspan(1);
    if (received_ == kDfuImageHeaderSize) {
      header_ = decode_dfu_image_header(header_bytes_);
      if (!header_.well_formed()) {
        fail(dfu::Status::kErrFile);
        return;
      }
      if (header_.length > targets_[alternate_].region.size - kDfuImageHeaderSize) {
        fail(dfu::Status::kErrAddress);  // larger than the slot: refused before any erase
        return;
      }
    }
  }
  if (!data.empty()) {
    if (data.size() > header_.length - (received_ - kDfuImageHeaderSize)) {
      fail(dfu::Status::kErrAddress);  // more bytes than the header announced
      return;
    }
    stream_crc_ = link::crc32_update(stream_crc_, data);
    const flash::WriteResult r = writer_.append(data);
    if (!r.ok()) {
      fail(to_dfu_status(r));
      return;
    }
    received_ += static_cast<std::uint32_t>(data.size());
  }
  state_ = dfu::State::kDnloadSync;
}

void DfuMode::manifest() noexcept {
  manifest_pending_ = false;
  if (received_ < kDfuImageHeaderSize || received_ - kDfuImageHeaderSize != header_.length) {
    fail(dfu::Status::kErrNotDone);
    return;
  }
  const flash::WriteResult finished = writer_.finish();
  if (!finished.ok()) {
    fail(to_dfu_status(finished));
    return;
  }
  if (link::crc32_end(stream_crc_) != header_.crc32) {
    fail(dfu::Status::kErrFile);
    return;
  }
  // Read back what was programmed.
  const std::uint32_t base = targets_[alternate_].region.offset + static_cast<std::uint32_t>(kDfuImageHeaderSize);
  std::uint32_t crc = link::crc32_begin();
  for (std::uint32_t done = 0; done < header_.length;) {
    const std::uint32_t left = header_.length - done;
    const std::uint32_t n = left < sizeof(block_) ? left : static_cast<std::uint32_t>(sizeof(block_));
    if (flash_.read(base + done, std::span<std::uint8_t>(block_, n)) != flash::FlashStatus::kOk) {
      fail(dfu::Status::kErrVerify);
      return;
    }
    crc = link::crc32_update(crc, std::span<const std::uint8_t>(block_, n));
    done += n;
  }
  if (link::crc32_end(crc) != header_.crc32) {
    fail(dfu::Status::kErrVerify);
    return;
  }
  const flash::WriteResult header_written = writer_.write_at(0, header_bytes_);
  if (!header_written.ok()) {
    fail(to_dfu_status(header_written));
    return;
  }
  ++images_written_;
  state_ = dfu::State::kManifestSync;
}

dfu::Status DfuMode::to_dfu_status(const flash::WriteResult& r) noexcept {
  switch (r.status) {
    case flash::FlashStatus::kOk:
      return dfu::Status::kOk;
    case flash::FlashStatus::kNotErased:
      return dfu::Status::kErrCheckErased;
    case flash::FlashStatus::kOutOfRange:
      return dfu::Status::kErrAddress;
    case flash::FlashStatus::kMisaligned:
    case flash::FlashStatus::kCrossesSector:
      return dfu::Status::kErrProg;
    case flash::FlashStatus::kWriteError:
    case flash::FlashStatus::kPowerLoss:
      return r.during_erase ? dfu::Status::kErrErase : dfu::Status::kErrWrite;
  }
  return dfu::Status::kErrUnknown;
}

bool DfuMode::configure(DeviceController&) noexcept {
  reset_to_idle();
  alternate_ = 0;
  return true;
}

void DfuMode::deconfigure() noexcept {
  reset_to_idle();
  alternate_ = 0;
}

bool DfuMode::set_alternate(std::uint8_t interface, std::uint8_t alternate) noexcept {
  if (interface != interface_ || alternate >= targets_.size()) return false;
  if (state_ == dfu::State::kDnBusy || state_ == dfu::State::kManifest) return false;
  alternate_ = alternate;
  reset_to_idle();
  return true;
}

std::uint8_t DfuMode::alternate(std::uint8_t) const noexcept { return alternate_; }

}  // namespace hadynet::usb
