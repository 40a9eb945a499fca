#include "firmware/model_update/slot_inspection.h"

#include <algorithm>
#include <array>

#include "firmware/crypto/sha256.h"
#include "firmware/model_update/image_check.h"
#include "firmware/model_update/slot_layout.h"
#include "firmware/model_update/trial_flags.h"

namespace hadynet::model_update {

namespace {

SlotStatus invalid(std::uint32_t sequence, UpdateError why) noexcept {
  return SlotStatus{SlotState::kInvalid, sequence, why};
}

}  // namespace

std::span<const std::uint8_t> slot_payload(std::span<const std::uint8_t> mapped_flash, const flash::FlashRegion& slot,
                                           std::uint32_t payload_length) noexcept {
  const std::uint64_t start = static_cast<std::uint64_t>(slot.offset) + kSlotPayloadOffset;
  if (start > mapped_flash.size() || payload_length > mapped_flash.size() - start) return {};
  return mapped_flash.subspan(static_cast<std::size_t>(start), payload_length);
}

SlotStatus inspect_slot(const flash::FlashDevice& device, const flash::FlashRegion& slot,
                        const SlotCheckContext& context, ModelImageHeader& header) noexcept {
  std::array<std::uint8_t, kImageHeaderSize> bytes{};
  if (device.read(slot.offset + kSlotHeaderOffset, bytes) != flash::FlashStatus::kOk) {
    return invalid(0, UpdateError::kFlashError);
  }
  if (std::all_of(bytes.begin(), bytes.end(), [](std::uint8_t b) { return b == 0xFF; })) {
    return SlotStatus{SlotState::kEmpty, 0, UpdateError::kOk};
  }
  if (decode_model_image_header(bytes, header) != HeaderFormat::kWellFormed) {
    return invalid(0, UpdateError::kMalformedHeader);
  }
  // The flags first: a slot marked invalid needs no signature check.
  TrialFlags flags;
  if (read_trial_flags(device, slot, flags) != flash::FlashStatus::kOk) {
    return invalid(header.sequence, UpdateError::kFlashError);
  }
  if (flags.invalid) return invalid(header.sequence, UpdateError::kMarkedInvalid);
  const UpdateError checked = check_image_header(bytes, context.identity, context.trusted_key, slot.size, header);
  if (checked != UpdateError::kOk) return invalid(header.sequence, checked);
  const std::span<const std::uint8_t> payload = slot_payload(context.mapped_flash, slot, header.payload_length);
  if (payload.size() != header.payload_length) return invalid(header.sequence, UpdateError::kBadSlotLayout);
  if (crypto::sha256(payload) != header.payload_sha256) {
    return invalid(header.sequence, UpdateError::kPayloadHashMismatch);
  }
  SlotState state = SlotState::kValid;
  if (flags.confirmed) {
    state = SlotState::kConfirmed;
  } else if (flags.tried) {
    state = SlotState::kTried;
  }
  return SlotStatus{state, header.sequence, UpdateError::kOk};
}

}  // namespace hadynet::model_update
