#include "test/model_update/signed_images.h"

#include <sodium.h>

#include <cstdlib>
#include <random>

namespace hadynet::model_update::test {

namespace {

void require_sodium() {
  if (sodium_init() < 0) std::abort();
}

}  // namespace

SigningKey signing_key(std::uint8_t seed) {
  require_sodium();
  std::array<std::uint8_t, crypto_sign_SEEDBYTES> seed_bytes{};
  seed_bytes.fill(seed);
  SigningKey k;
  crypto_sign_seed_keypair(k.public_key.data(), k.secret_key.data(), seed_bytes.data());
  return k;
}

Bytes random_bytes(std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Bytes out(count);
  for (std::uint8_t& b : out) b = static_cast<std::uint8_t>(rng() >> 24);
  return out;
}

ModelImageHeader header_for(const ModelIdentity& identity, std::uint32_t sequence) {
  ModelImageHeader h;
  h.contract_version = identity.contract_version;
  h.numeric = identity.numeric;
  h.sequence = sequence;
  h.shape_id = identity.shape_id;
  h.payload_length = identity.payload_length;
  h.self_test_checksum = 0xC0FFEE00u + sequence;
  h.dims = {18, 7, 18, 2, 64, 9, 60, 10};
  for (std::size_t i = 0; i < h.frac_bits.size(); ++i) h.frac_bits[i] = static_cast<std::uint8_t>(8 + i);
  h.model_hash = 0xCBF29CE484222325ull ^ sequence;
  return h;
}

Bytes sign_image_claiming(ModelImageHeader header, std::span<const std::uint8_t> payload, const SigningKey& key,
                          const PublicKey& claimed_key) {
  require_sodium();
  header.payload_length = static_cast<std::uint32_t>(payload.size());
  crypto_hash_sha256(header.payload_sha256.data(), payload.data(), payload.size());
  header.public_key = claimed_key;
  header.signature = {};
  Bytes image(kImageHeaderSize + payload.size());
  const std::span<std::uint8_t, kImageHeaderSize> head(image.data(), kImageHeaderSize);
  encode_model_image_header(header, head);
  crypto_sign_detached(header.signature.data(), nullptr, image.data(), kSignedBytes, key.secret_key.data());
  encode_model_image_header(header, head);
  std::copy(payload.begin(), payload.end(), image.begin() + kImageHeaderSize);
  return image;
}

Bytes sign_image(ModelImageHeader header, std::span<const std::uint8_t> payload, const SigningKey& key) {
  return sign_image_claiming(header, payload, key, key.public_key);
}

std::span<const std::uint8_t> header_of(const Bytes& image) {
  return std::span<const std::uint8_t>(image).first(kImageHeaderSize);
}

std::span<const std::uint8_t> payload_of(const Bytes& image) {
  return std::span<const std::uint8_t>(image).subspan(kImageHeaderSize);
}

}  // namespace hadynet::model_update::test
