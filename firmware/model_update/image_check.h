// Everything a device can check from an image header alone, except the
// sequence rule (which needs the slots' state; ModelSlots applies it):
// well-formed, contract/numeric/shape of this firmware, fits a slot, the
// exact payload length, signed with the device's trusted key, and the
// Ed25519 signature over header bytes [0, 192). The payload's SHA-256 is
// checked by whoever has the payload (the update stream, the boot's slot
// check). Used by begin_update() before anything is erased and by every
// boot's slot check, so both refuse exactly the same headers.
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_IMAGE_CHECK_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_IMAGE_CHECK_H_

#include <cstdint>
#include <span>

#include "firmware/model_update/model_identity.h"
#include "firmware/model_update/model_image.h"
#include "firmware/model_update/update_error.h"

namespace hadynet::model_update {

// Decodes `bytes` into `header` and checks it; the first failing check in
// the order of UpdateError's header group (malformed, contract, numeric,
// shape, too large, length, key, signature). `header` is fully written
// unless the result is kMalformedHeader. `slot_size`: bytes of one slot.
UpdateError check_image_header(std::span<const std::uint8_t, kImageHeaderSize> bytes, const ModelIdentity& identity,
                               const PublicKey& trusted_key, std::uint32_t slot_size,
                               ModelImageHeader& header) noexcept;

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_IMAGE_CHECK_H_
