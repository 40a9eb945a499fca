// What an image must match to run on this firmware: the model contract,
// the numeric, the shape of the compiled-in model and its exact payload
// length. The firmware fills it from its generated model; the image's
// header carries the same values (model_image.h).
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_MODEL_IDENTITY_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_MODEL_IDENTITY_H_

#include <array>
#include <cstdint>

#include "firmware/model_update/model_image.h"

namespace hadynet::model_update {

struct ModelIdentity {
  std::uint16_t contract_version = 0;
  std::uint8_t numeric = kNumericQ15;  // kNumericQ15 or kNumericF32
  std::uint64_t shape_id = 0;
  std::uint32_t payload_length = 0;    // bytes of this firmware's model payload
};

// An Ed25519 public key (32 bytes).
using PublicKey = std::array<std::uint8_t, kPublicKeyBytes>;

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_MODEL_IDENTITY_H_
