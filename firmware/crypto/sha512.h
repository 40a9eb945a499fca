// SHA-512 (FIPS 180-4 §6.4): streaming and one-shot. Portable, no heap, no
// exceptions. Bytes go in and out in the standard's order: the digest is
// the eight 64-bit hash words, each big-endian, H0 first.
//
// Messages may be up to 2^61 - 1 bytes long (the length is counted in a
// 64-bit byte counter; the padding's 128-bit bit length is formed from it);
// longer input is not detected. Not constant time in the message length
// (irrelevant here: it hashes public data).
//
// Stack: about 0.35 KiB in update()/finish() (the 16-word message schedule and
// the working variables) besides the object itself (~208 bytes).
#ifndef HADYNET_FIRMWARE_CRYPTO_SHA512_H_
#define HADYNET_FIRMWARE_CRYPTO_SHA512_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace hadynet::crypto {

inline constexpr std::size_t kSha512Bytes = 64;

class Sha512 {
 public:
  static constexpr std::size_t kBlockBytes = 128;

  Sha512() noexcept;
  // Appends bytes to the message (any length, also empty).
  void update(std::span<const std::uint8_t> data) noexcept;
  // Pads, returns the digest of everything given since construction (or the
  // last finish()), and resets the object to the empty message for reuse.
  std::array<std::uint8_t, kSha512Bytes> finish() noexcept;

 private:
  void reset() noexcept;

  std::array<std::uint64_t, 8> state_{};
  std::array<std::uint8_t, kBlockBytes> block_{};  // the unprocessed tail of the message
  std::size_t block_used_ = 0;                      // bytes of block_ in use, < kBlockBytes
  std::uint64_t message_bytes_ = 0;                 // total length so far
};

// SHA-512 of one whole message.
std::array<std::uint8_t, kSha512Bytes> sha512(std::span<const std::uint8_t> data) noexcept;

}  // namespace hadynet::crypto

#endif  // HADYNET_FIRMWARE_CRYPTO_SHA512_H_
