// Writes one image into one slot as a stream (slot_layout.h): the payload
// through a FlashRegionWriter from slot offset 1024 (sectors erased lazily,
// so the first append erases the slot's old header and flags, and nothing is
// erased before it), hashed as it arrives; finish() checks the exact length
// and the stream's SHA-256 against the header's, reads the payload back
// from flash and hashes it again, then programs the 256-byte header at
// slot offset 0 and reads it back. Any failure ends the stream and leaves
// the slot without a header (or untouched if nothing was erased yet).
// The header must have been checked already (image_check.h).
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_UPDATE_STREAM_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_UPDATE_STREAM_H_

#include <array>
#include <cstdint>
#include <span>

#include "firmware/crypto/sha256.h"
#include "firmware/flash/flash_device.h"
#include "firmware/flash/flash_region_writer.h"
#include "firmware/model_update/model_image.h"
#include "firmware/model_update/update_error.h"

namespace hadynet::model_update {

class SlotUpdateStream {
 public:
  // Starts a stream of `header.payload_length` bytes into `slot`; erases
  // nothing. kFlashError if the writer refuses the region (alignment).
  UpdateError begin(flash::FlashDevice& device, const flash::FlashRegion& slot,
                    std::span<const std::uint8_t, kImageHeaderSize> header_bytes,
                    const ModelImageHeader& header) noexcept;
  // Any chunking. kTooManyBytes (before writing any byte of the chunk) if
  // the chunk goes past the header's length.
  UpdateError append(std::span<const std::uint8_t> bytes) noexcept;
  UpdateError finish() noexcept;
  // Ends the stream without a header (the slot keeps what was written).
  void abandon() noexcept { active_ = false; }

  bool active() const noexcept { return active_; }
  // Whether the stream passed any byte to the flash (the slot's header may be gone).
  bool touched_flash() const noexcept { return touched_; }
  std::uint32_t received() const noexcept { return received_; }
  // The flash's status of the last kFlashError (kOk if none).
  flash::FlashStatus flash_status() const noexcept { return flash_status_; }

 private:
  UpdateError fail(UpdateError e) noexcept;
  UpdateError fail_flash(flash::FlashStatus s) noexcept;
  bool payload_reads_back() noexcept;
  bool header_reads_back() noexcept;

  flash::FlashDevice* device_ = nullptr;
  flash::FlashRegion slot_{};
  flash::FlashRegionWriter writer_;
  crypto::Sha256 hash_;
  std::array<std::uint8_t, kImageHeaderSize> header_bytes_{};
  std::array<std::uint8_t, kPayloadHashBytes> expected_sha256_{};
  std::uint32_t length_ = 0;    // payload bytes expected
  std::uint32_t received_ = 0;  // payload bytes accepted
  bool active_ = false;
  bool touched_ = false;
  flash::FlashStatus flash_status_ = flash::FlashStatus::kOk;
};

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_UPDATE_STREAM_H_
