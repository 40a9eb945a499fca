// Integers mod L, L = 2^252 + 27742317777372353535851937790883648493 (the
// prime order of the Ed25519 base point, RFC 8032 §5.1), for verification:
// reading S, reducing SHA-512(R || A || M), and recoding scalars for the
// double-scalar multiplication. Variable time (public data only).
#ifndef HADYNET_FIRMWARE_CRYPTO_SCALAR25519_H_
#define HADYNET_FIRMWARE_CRYPTO_SCALAR25519_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace hadynet::crypto::scalar25519 {

// A value in [0, L): eight 32-bit limbs, least significant first.
struct Scalar {
  std::uint32_t limb[8];
};

inline constexpr Scalar kL = {
    {0x5cf5d3ed, 0x5812631a, 0xa2f79cd6, 0x14def9de, 0x00000000, 0x00000000, 0x00000000, 0x10000000}};

// Reads a 32-byte little-endian integer. Returns false, leaving `out`
// unchanged, if it is >= L: a non-canonical S, which verification rejects
// (RFC 8032 §5.1.7 step 1; libsodium 1.0.18 likewise).
bool from_canonical_bytes(Scalar& out, std::span<const std::uint8_t, 32> bytes) noexcept;

// A 64-byte little-endian integer (a SHA-512 digest, RFC 8032 §5.1.7 step 2)
// reduced mod L.
Scalar reduce_wide(std::span<const std::uint8_t, 64> bytes) noexcept;

// 32 little-endian bytes.
std::array<std::uint8_t, 32> to_bytes(const Scalar& s) noexcept;

// Width-w non-adjacent form, 2 <= w <= 7: s = sum of digits[i] * 2^i with
// every digit 0 or odd in [-(2^(w-1) - 1), 2^(w-1) - 1], and each non-zero
// digit followed by at least w - 1 zeros (about one addition per w + 1
// doublings). For s < L (< 2^253) only digits[0..253] can be non-zero.
inline constexpr std::size_t kNafDigits = 256;
void naf(std::int8_t (&digits)[kNafDigits], const Scalar& s, int width) noexcept;

}  // namespace hadynet::crypto::scalar25519

#endif  // HADYNET_FIRMWARE_CRYPTO_SCALAR25519_H_
