#include "firmware/model_update/image_check.h"

#include "firmware/crypto/ed25519_verify.h"
#include "firmware/model_update/slot_layout.h"

namespace hadynet::model_update {

UpdateError check_image_header(std::span<const std::uint8_t, kImageHeaderSize> bytes, const ModelIdentity& identity,
                               const PublicKey& trusted_key, std::uint32_t slot_size,
                               ModelImageHeader& header) noexcept {
  if (decode_model_image_header(bytes, header) != HeaderFormat::kWellFormed) return UpdateError::kMalformedHeader;
  if (header.contract_version != identity.contract_version) return UpdateError::kContractMismatch;
  if (header.numeric != identity.numeric) return UpdateError::kNumericMismatch;
  if (header.shape_id != identity.shape_id) return UpdateError::kShapeMismatch;
  if (slot_size < kSlotPayloadOffset || header.payload_length > slot_size - kSlotPayloadOffset) {
    return UpdateError::kImageTooLarge;
  }
  if (header.payload_length != identity.payload_length) return UpdateError::kPayloadLengthMismatch;
  if (header.public_key != trusted_key) return UpdateError::kSignedByOtherKey;
  const std::span<const std::uint8_t, kSignatureBytes> signature(header.signature);
  const std::span<const std::uint8_t, kPublicKeyBytes> key(trusted_key);
  if (!crypto::ed25519_verify(signature, bytes.first(kSignedBytes), key)) return UpdateError::kBadSignature;
  return UpdateError::kOk;
}

}  // namespace hadynet::model_update
