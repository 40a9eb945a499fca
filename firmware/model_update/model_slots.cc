// ModelSlots: construction, the slot layout check and the shared helpers.
// The boot rule is in model_slots_boot.cc, the update in
// model_slots_update.cc.
#include "firmware/model_update/model_slots.h"

#include <algorithm>

#include "firmware/model_update/slot_layout.h"

namespace hadynet::model_update {

namespace {

bool slot_layout_ok(const flash::FlashDevice& device, const flash::FlashRegion& a, const flash::FlashRegion& b,
                    std::uint32_t payload_length, std::span<const std::uint8_t> mapped) noexcept {
  const std::span<const flash::FlashSector> sectors = device.sectors();
  if (!flash::region_is_sector_aligned(sectors, a) || !flash::region_is_sector_aligned(sectors, b)) return false;
  if (a.size != b.size) return false;
  const bool disjoint = a.offset + static_cast<std::uint64_t>(a.size) <= b.offset ||
                        b.offset + static_cast<std::uint64_t>(b.size) <= a.offset;
  if (!disjoint) return false;
  if (a.size < kSlotPayloadOffset || payload_length > a.size - kSlotPayloadOffset) return false;
  if (mapped.size() < flash::flash_size(device)) return false;
  // The flags are written one 16-byte unit each, the stream by the region
  // writer (program units of at most 16 bytes).
  const std::uint32_t alignment = device.program_alignment();
  return alignment != 0 && kSlotFlagUnitBytes % alignment == 0 &&
         alignment <= flash::FlashRegionWriter::kMaxAlignment;
}

}  // namespace

ModelSlots::ModelSlots(flash::FlashDevice& flash, const flash::FlashRegion& slot_a, const flash::FlashRegion& slot_b,
                       const ModelIdentity& identity,
                       std::span<const std::uint8_t, kPublicKeyBytes> trusted_public_key,
                       std::span<const std::uint8_t> mapped_flash) noexcept
    : flash_(flash), slots_{slot_a, slot_b}, context_{mapped_flash, identity, {}} {
  std::copy(trusted_public_key.begin(), trusted_public_key.end(), context_.trusted_key.begin());
  if (!slot_layout_ok(flash, slot_a, slot_b, identity.payload_length, mapped_flash)) {
    layout_error_ = UpdateError::kBadSlotLayout;
  }
}

void ModelSlots::inspect(SlotId slot) noexcept {
  const std::size_t i = slot_index(slot);
  status_[i] = inspect_slot(flash_, slots_[i], context_, headers_[i]);
}

std::uint32_t ModelSlots::highest_usable_sequence() const noexcept {
  std::uint32_t highest = 0;
  for (const SlotStatus& s : status_) {
    if (holds_usable_image(s.state) && s.sequence > highest) highest = s.sequence;
  }
  return highest;
}

}  // namespace hadynet::model_update
