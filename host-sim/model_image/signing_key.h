// The owner's Ed25519 key for model images (docs/model-update.md, "Keys"),
// with libsodium: `hadynet keygen` writes KEY (the secret key) and KEY.pub
// (the public key the firmware is built with); `hadynet model-image --key
// KEY` signs. Files are text, one key per file:
//
//   KEY      # comment lines ...
//            secret <128 hex digits: libsodium's 64-byte secret key, seed || public key>
//   KEY.pub  # comment lines ...
//            public <64 hex digits>
//
// A development key (the repository's keys/development.key, or any key made
// with --development) says so in both files' comments and in
// `hadynet model-image`'s output: anyone with the repository can sign with it.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>

namespace hadynet::host {

// A key file that cannot be read or parsed; the message names the file (and line).
class KeyFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using PublicKey = std::array<std::uint8_t, 32>;

struct SigningKey {
  std::array<std::uint8_t, 64> secret{};  // libsodium's crypto_sign secret key
  PublicKey public_key{};
  bool development = false;  // the file's comment marks it as a development key
};

// A fresh key from the operating system's random source.
SigningKey generate_signing_key(bool development);

// Writes `path` (mode 0600) and `path`.pub; refuses to overwrite an existing
// secret key file (KeyFileError).
void write_signing_key(const std::filesystem::path& path, const SigningKey& key);

SigningKey read_signing_key(const std::filesystem::path& path);
// A .pub file (or a secret key file: its public half); `development` is set
// when the file says so.
PublicKey read_public_key(const std::filesystem::path& path, bool* development = nullptr);

// Ed25519 signature of `message` (libsodium crypto_sign_detached).
std::array<std::uint8_t, 64> sign(const SigningKey& key, std::span<const std::uint8_t> message);
// SHA-256 (libsodium crypto_hash_sha256).
std::array<std::uint8_t, 32> sha256(std::span<const std::uint8_t> bytes);

std::string hex(std::span<const std::uint8_t> bytes);

}  // namespace hadynet::host
