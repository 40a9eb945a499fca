// One slot's check, as every boot does it: read the header, decide empty /
// usable / invalid. Usable means: the header is well-formed and passes
// check_image_header() (identity, size, trusted key, signature), the
// payload's SHA-256 (hashed in the mapped flash view, the bytes the runtime
// will read) equals the header's, and the "invalid" flag is not set; then
// the tried/confirmed flags give kValid, kTried or kConfirmed.
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_INSPECTION_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_INSPECTION_H_

#include <cstdint>
#include <span>

#include "firmware/flash/flash_device.h"
#include "firmware/flash/flash_region_writer.h"
#include "firmware/model_update/model_identity.h"
#include "firmware/model_update/model_image.h"
#include "firmware/model_update/slot_status.h"

namespace hadynet::model_update {

// The flash's memory-mapped view and the trust a slot is checked against.
struct SlotCheckContext {
  std::span<const std::uint8_t> mapped_flash;  // byte i = device offset i
  ModelIdentity identity{};
  PublicKey trusted_key{};
};

// The status of `slot`; `header` holds the decoded header when the status
// has a sequence (state other than kEmpty, last_error not kMalformedHeader
// or kFlashError). A read error gives kInvalid with kFlashError.
SlotStatus inspect_slot(const flash::FlashDevice& device, const flash::FlashRegion& slot,
                        const SlotCheckContext& context, ModelImageHeader& header) noexcept;

// The payload bytes of an image of `payload_length` bytes in `slot`, in the
// mapped view (empty if the view does not cover them).
std::span<const std::uint8_t> slot_payload(std::span<const std::uint8_t> mapped_flash, const flash::FlashRegion& slot,
                                           std::uint32_t payload_length) noexcept;

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_SLOT_INSPECTION_H_
