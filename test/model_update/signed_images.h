// Model images signed on the host with libsodium, as the image writer will
// make them: a header filled from a spec, the payload's SHA-256, the
// signer's public key, an Ed25519 signature over header bytes [0, 192).
#ifndef HADYNET_TEST_MODEL_UPDATE_SIGNED_IMAGES_H_
#define HADYNET_TEST_MODEL_UPDATE_SIGNED_IMAGES_H_

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "firmware/model_update/model_identity.h"
#include "firmware/model_update/model_image.h"

namespace hadynet::model_update::test {

using Bytes = std::vector<std::uint8_t>;

struct SigningKey {
  PublicKey public_key{};
  std::array<std::uint8_t, 64> secret_key{};  // libsodium's seed || public key
};

// A deterministic key pair from a one-byte seed (crypto_sign_seed_keypair).
SigningKey signing_key(std::uint8_t seed);

// `count` pseudo-random bytes from `seed` (deterministic).
Bytes random_bytes(std::size_t count, std::uint32_t seed);

// A header for `identity` with `sequence`, information fields filled with
// plausible values; public key, hash and signature still zero.
ModelImageHeader header_for(const ModelIdentity& identity, std::uint32_t sequence);

// Header bytes + payload: sets the header's payload length, SHA-256 and
// public key from `payload` and `key`, then signs.
Bytes sign_image(ModelImageHeader header, std::span<const std::uint8_t> payload, const SigningKey& key);

// The same, but the header states `claimed_key` as the signer's key while
// `key` signs (a forgery attempt).
Bytes sign_image_claiming(ModelImageHeader header, std::span<const std::uint8_t> payload, const SigningKey& key,
                          const PublicKey& claimed_key);

// The header bytes of an image.
std::span<const std::uint8_t> header_of(const Bytes& image);
std::span<const std::uint8_t> payload_of(const Bytes& image);

}  // namespace hadynet::model_update::test

#endif  // HADYNET_TEST_MODEL_UPDATE_SIGNED_IMAGES_H_
