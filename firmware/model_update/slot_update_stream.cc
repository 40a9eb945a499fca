#include "firmware/model_update/slot_update_stream.h"

#include <algorithm>

#include "firmware/model_update/slot_layout.h"

namespace hadynet::model_update {

namespace {

constexpr std::size_t kReadBackChunk = 64;  // bytes read per call (stack buffer)

}  // namespace

UpdateError SlotUpdateStream::fail(UpdateError e) noexcept {
  active_ = false;
  return e;
}

UpdateError SlotUpdateStream::fail_flash(flash::FlashStatus s) noexcept {
  flash_status_ = s;
  return fail(UpdateError::kFlashError);
}

UpdateError SlotUpdateStream::begin(flash::FlashDevice& device, const flash::FlashRegion& slot,
                                    std::span<const std::uint8_t, kImageHeaderSize> header_bytes,
                                    const ModelImageHeader& header) noexcept {
  device_ = &device;
  slot_ = slot;
  std::copy(header_bytes.begin(), header_bytes.end(), header_bytes_.begin());
  expected_sha256_ = header.payload_sha256;
  length_ = header.payload_length;
  received_ = 0;
  touched_ = false;
  flash_status_ = flash::FlashStatus::kOk;
  hash_ = crypto::Sha256{};
  active_ = true;
  const flash::WriteResult r = writer_.begin(device, slot, kSlotPayloadOffset);
  if (!r.ok()) return fail_flash(r.status);
  return UpdateError::kOk;
}

UpdateError SlotUpdateStream::append(std::span<const std::uint8_t> bytes) noexcept {
  if (!active_) return UpdateError::kNoUpdateInProgress;
  if (bytes.size() > length_ - received_) return fail(UpdateError::kTooManyBytes);
  if (bytes.empty()) return UpdateError::kOk;
  hash_.update(bytes);
  touched_ = true;
  const flash::WriteResult r = writer_.append(bytes);
  if (!r.ok()) return fail_flash(r.status);
  received_ += static_cast<std::uint32_t>(bytes.size());
  return UpdateError::kOk;
}

bool SlotUpdateStream::payload_reads_back() noexcept {
  crypto::Sha256 again;
  std::array<std::uint8_t, kReadBackChunk> chunk{};
  for (std::uint32_t done = 0; done < length_;) {
    const std::uint32_t n = std::min<std::uint32_t>(kReadBackChunk, length_ - done);
    const std::span<std::uint8_t> part(chunk.data(), n);
    const flash::FlashStatus s = device_->read(slot_.offset + kSlotPayloadOffset + done, part);
    if (s != flash::FlashStatus::kOk) {
      flash_status_ = s;
      return false;
    }
    again.update(part);
    done += n;
  }
  return again.finish() == expected_sha256_;
}

bool SlotUpdateStream::header_reads_back() noexcept {
  std::array<std::uint8_t, kImageHeaderSize> back{};
  const flash::FlashStatus s = device_->read(slot_.offset + kSlotHeaderOffset, back);
  if (s != flash::FlashStatus::kOk) {
    flash_status_ = s;
    return false;
  }
  return back == header_bytes_;
}

UpdateError SlotUpdateStream::finish() noexcept {
  if (!active_) return UpdateError::kNoUpdateInProgress;
  if (received_ != length_) return fail(UpdateError::kTruncated);
  // A zero-length payload erased nothing yet: the header's sector must be
  // erased by write_at() below, which the writer does.
  const flash::WriteResult padded = writer_.finish();
  if (!padded.ok()) return fail_flash(padded.status);
  if (hash_.finish() != expected_sha256_) return fail(UpdateError::kPayloadHashMismatch);
  if (!payload_reads_back()) {
    return flash_status_ != flash::FlashStatus::kOk ? fail(UpdateError::kFlashError)
                                                    : fail(UpdateError::kReadBackMismatch);
  }
  touched_ = true;
  const flash::WriteResult h = writer_.write_at(kSlotHeaderOffset, header_bytes_);
  if (!h.ok()) return fail_flash(h.status);
  if (!header_reads_back()) {
    return flash_status_ != flash::FlashStatus::kOk ? fail(UpdateError::kFlashError)
                                                    : fail(UpdateError::kReadBackMismatch);
  }
  active_ = false;
  return UpdateError::kOk;
}

}  // namespace hadynet::model_update
