#include "firmware/crypto/scalar25519.h"

namespace hadynet::crypto::scalar25519 {
namespace {

std::uint32_t load_le32(const std::uint8_t* p) noexcept {
  return std::uint32_t{p[0]} | (std::uint32_t{p[1]} << 8) | (std::uint32_t{p[2]} << 16) | (std::uint32_t{p[3]} << 24);
}

// a >= b as 256-bit integers.
bool greater_equal(const Scalar& a, const Scalar& b) noexcept {
  for (int i = 7; i >= 0; --i) {
    if (a.limb[i] != b.limb[i]) return a.limb[i] > b.limb[i];
  }
  return true;
}

// a -= b, for a >= b.
void subtract_in_place(Scalar& a, const Scalar& b) noexcept {
  std::uint32_t borrow = 0;
  for (int i = 0; i < 8; ++i) {
    const std::uint64_t t = std::uint64_t{a.limb[i]} - b.limb[i] - borrow;
    a.limb[i] = static_cast<std::uint32_t>(t);
    borrow = static_cast<std::uint32_t>(t >> 63);
  }
}

// Bit i of s (0 beyond bit 255).
std::uint32_t bit(const Scalar& s, int i) noexcept {
  return i < 256 ? (s.limb[i >> 5] >> (i & 31)) & 1u : 0u;
}

}  // namespace

bool from_canonical_bytes(Scalar& out, std::span<const std::uint8_t, 32> bytes) noexcept {
  Scalar s{};
  for (int i = 0; i < 8; ++i) s.limb[i] = load_le32(bytes.data() + 4 * i);
  if (greater_equal(s, kL)) return false;
  out = s;
  return true;
}

Scalar reduce_wide(std::span<const std::uint8_t, 64> bytes) noexcept {
  // Horner's rule over the bits, most significant first: r <- 2r + bit,
  // then r <- r - L if r >= L. r stays below L < 2^253, so 2r + 1 < 2^254
  // fits in 256 bits.
  Scalar r{};
  for (int byte = 63; byte >= 0; --byte) {
    for (int b = 7; b >= 0; --b) {
      std::uint32_t carry = (bytes[static_cast<std::size_t>(byte)] >> b) & 1u;
      for (int i = 0; i < 8; ++i) {
        const std::uint32_t v = r.limb[i];
        r.limb[i] = (v << 1) | carry;
        carry = v >> 31;
      }
      if (greater_equal(r, kL)) subtract_in_place(r, kL);
    }
  }
  return r;
}

std::array<std::uint8_t, 32> to_bytes(const Scalar& s) noexcept {
  std::array<std::uint8_t, 32> out{};
  for (int i = 0; i < 8; ++i) {
    for (int k = 0; k < 4; ++k) out[4 * i + k] = static_cast<std::uint8_t>(s.limb[i] >> (8 * k));
  }
  return out;
}

void naf(std::int8_t (&digits)[kNafDigits], const Scalar& s, int width) noexcept {
  // Scan from the least significant bit with a pending carry (+1 at `pos`
  // left over from a negative digit). Where the remaining value is odd, take
  // its low `width` bits v (odd) as the digit, or v - 2^width when
  // v > 2^(width-1) and carry 1 into bit pos + width; either way bits
  // pos+1 .. pos+width-1 of what remains become zero. A carry needs bit
  // pos + width - 1 set, so for s < 2^253 it lands at bit 253 at the latest:
  // nothing is left past the array.
  const std::uint32_t half = std::uint32_t{1} << (width - 1);
  for (auto& d : digits) d = 0;
  std::uint32_t carry = 0;
  int pos = 0;
  while (pos < static_cast<int>(kNafDigits)) {
    if (bit(s, pos) + carry != 1) {  // even here (0, or 2: the carry moves up)
      ++pos;
      continue;
    }
    std::uint32_t v = carry;
    for (int k = 0; k < width; ++k) v += bit(s, pos + k) << k;
    if (v > half) {
      digits[pos] = static_cast<std::int8_t>(static_cast<int>(v) - static_cast<int>(2 * half));
      carry = 1;
    } else {
      digits[pos] = static_cast<std::int8_t>(v);
      carry = 0;
    }
    pos += width;
  }
}

}  // namespace hadynet::crypto::scalar25519
