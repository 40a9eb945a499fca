// Arithmetic in the field GF(p), p = 2^255 - 19, for Ed25519 verification
// (RFC 8032 §5.1).
//
// An Element is a 256-bit integer in eight 32-bit limbs, least significant
// first, standing for its residue mod p. Values are kept loosely reduced:
// every integer in [0, 2^256) is a valid representation, every operation
// accepts and returns such values, and carries out of bit 255 are folded
// back with 2^256 = 38 (mod p). Only canonical() and to_bytes() produce the
// unique residue in [0, p); compare elements with equal(), never limb by limb.
//
// Everything is constexpr: edwards25519.cc has the compiler build the base
// point's table. At run time add, sub, mul and square go to out-of-line
// copies (field25519.cc) rather than being inlined at every use.
// Variable time: verification handles only public data, so nothing here
// needs to be constant time, and nothing here is.
//
// Stack: at most ~0.1 KiB per call (a 512-bit product and a few limbs).
#ifndef HADYNET_FIRMWARE_CRYPTO_FIELD25519_H_
#define HADYNET_FIRMWARE_CRYPTO_FIELD25519_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

namespace hadynet::crypto::gf25519 {

struct Element {
  std::uint32_t limb[8];
};

inline constexpr Element kZero = {{0, 0, 0, 0, 0, 0, 0, 0}};
inline constexpr Element kOne = {{1, 0, 0, 0, 0, 0, 0, 0}};
// p itself, for the final reduction.
inline constexpr Element kP = {
    {0xffffffed, 0xffffffff, 0xffffffff, 0xffffffff, 0xffffffff, 0xffffffff, 0xffffffff, 0x7fffffff}};

namespace internal {

// r + carry * 2^256, reduced again below 2^256 (each unit of carry is 38).
constexpr void fold_carry(Element& r, std::uint32_t carry) noexcept {
  while (carry != 0) {
    std::uint64_t acc = std::uint64_t{carry} * 38u;
    for (int i = 0; i < 8 && acc != 0; ++i) {
      acc += r.limb[i];
      r.limb[i] = static_cast<std::uint32_t>(acc);
      acc >>= 32;
    }
    carry = static_cast<std::uint32_t>(acc);
  }
}

// r - borrow * 2^256 (r wrapped below zero `borrow` times), brought back
// into [0, 2^256): each wrap is undone by subtracting 38.
constexpr void fold_borrow(Element& r, std::uint32_t borrow) noexcept {
  while (borrow != 0) {
    std::uint64_t t = std::uint64_t{r.limb[0]} - 38u;
    r.limb[0] = static_cast<std::uint32_t>(t);
    std::uint32_t b = static_cast<std::uint32_t>(t >> 63);
    for (int i = 1; i < 8 && b != 0; ++i) {
      t = std::uint64_t{r.limb[i]} - b;
      r.limb[i] = static_cast<std::uint32_t>(t);
      b = static_cast<std::uint32_t>(t >> 63);
    }
    borrow = b;
  }
}

// A 512-bit integer t[0..15] (little-endian limbs) reduced below 2^256:
// t = lo + 2^256 hi = lo + 38 hi (mod p).
constexpr Element reduce_wide(const std::uint32_t (&t)[16]) noexcept {
  Element r{};
  std::uint64_t acc = 0;
  for (int i = 0; i < 8; ++i) {
    acc += std::uint64_t{t[i]} + std::uint64_t{t[i + 8]} * 38u;
    r.limb[i] = static_cast<std::uint32_t>(acc);
    acc >>= 32;
  }
  fold_carry(r, static_cast<std::uint32_t>(acc));
  return r;
}

// a >= b as 256-bit integers.
constexpr bool greater_equal(const Element& a, const Element& b) noexcept {
  for (int i = 7; i >= 0; --i) {
    if (a.limb[i] != b.limb[i]) return a.limb[i] > b.limb[i];
  }
  return true;
}

// a - b for a >= b (no wrap).
constexpr Element subtract_smaller(const Element& a, const Element& b) noexcept {
  Element r{};
  std::uint32_t borrow = 0;
  for (int i = 0; i < 8; ++i) {
    const std::uint64_t t = std::uint64_t{a.limb[i]} - b.limb[i] - borrow;
    r.limb[i] = static_cast<std::uint32_t>(t);
    borrow = static_cast<std::uint32_t>(t >> 63);
  }
  return r;
}

constexpr Element add_impl(const Element& a, const Element& b) noexcept {
  Element r{};
  std::uint64_t acc = 0;
  for (int i = 0; i < 8; ++i) {
    acc += std::uint64_t{a.limb[i]} + b.limb[i];
    r.limb[i] = static_cast<std::uint32_t>(acc);
    acc >>= 32;
  }
  fold_carry(r, static_cast<std::uint32_t>(acc));
  return r;
}

constexpr Element sub_impl(const Element& a, const Element& b) noexcept {
  Element r{};
  std::uint32_t borrow = 0;
  for (int i = 0; i < 8; ++i) {
    const std::uint64_t t = std::uint64_t{a.limb[i]} - b.limb[i] - borrow;
    r.limb[i] = static_cast<std::uint32_t>(t);
    borrow = static_cast<std::uint32_t>(t >> 63);
  }
  fold_borrow(r, borrow);
  return r;
}

// Schoolbook product (operand scanning: every partial sum a_i b_j + t + carry
// fits in 64 bits), then the 512-bit result folded with 2^256 = 38.
constexpr Element mul_impl(const Element& a, const Element& b) noexcept {
  std::uint32_t t[16] = {};
  for (int i = 0; i < 8; ++i) {
    std::uint64_t acc = 0;
    for (int j = 0; j < 8; ++j) {
      acc += std::uint64_t{a.limb[i]} * b.limb[j] + t[i + j];
      t[i + j] = static_cast<std::uint32_t>(acc);
      acc >>= 32;
    }
    t[i + 8] = static_cast<std::uint32_t>(acc);
  }
  return reduce_wide(t);
}

// a^2 with the 28 cross products computed once and doubled.
constexpr Element square_impl(const Element& a) noexcept {
  std::uint32_t t[16] = {};
  for (int i = 0; i < 7; ++i) {
    std::uint64_t acc = 0;
    for (int j = i + 1; j < 8; ++j) {
      acc += std::uint64_t{a.limb[i]} * a.limb[j] + t[i + j];
      t[i + j] = static_cast<std::uint32_t>(acc);
      acc >>= 32;
    }
    t[i + 8] = static_cast<std::uint32_t>(acc);
  }
  // Twice the cross products (they are below 2^511, so no bit is lost).
  std::uint32_t high_bit = 0;
  for (int k = 0; k < 16; ++k) {
    const std::uint32_t v = t[k];
    t[k] = (v << 1) | high_bit;
    high_bit = v >> 31;
  }
  // Plus the squares a_i^2 at limb 2i.
  std::uint64_t acc = 0;
  for (int i = 0; i < 8; ++i) {
    acc += std::uint64_t{a.limb[i]} * a.limb[i] + t[2 * i];
    t[2 * i] = static_cast<std::uint32_t>(acc);
    acc >>= 32;
    acc += t[2 * i + 1];
    t[2 * i + 1] = static_cast<std::uint32_t>(acc);
    acc >>= 32;
  }
  return reduce_wide(t);
}

// Out-of-line copies of the above (field25519.cc), which run-time calls go
// to: inlined at every use they doubled the code size on the MCU and made
// verification slower.
Element add_out_of_line(const Element& a, const Element& b) noexcept;
Element sub_out_of_line(const Element& a, const Element& b) noexcept;
Element mul_out_of_line(const Element& a, const Element& b) noexcept;
Element square_out_of_line(const Element& a) noexcept;

}  // namespace internal

constexpr Element add(const Element& a, const Element& b) noexcept {
  if (std::is_constant_evaluated()) return internal::add_impl(a, b);
  return internal::add_out_of_line(a, b);
}

constexpr Element sub(const Element& a, const Element& b) noexcept {
  if (std::is_constant_evaluated()) return internal::sub_impl(a, b);
  return internal::sub_out_of_line(a, b);
}

constexpr Element neg(const Element& a) noexcept { return sub(kZero, a); }

constexpr Element mul(const Element& a, const Element& b) noexcept {
  if (std::is_constant_evaluated()) return internal::mul_impl(a, b);
  return internal::mul_out_of_line(a, b);
}

constexpr Element square(const Element& a) noexcept {
  if (std::is_constant_evaluated()) return internal::square_impl(a);
  return internal::square_out_of_line(a);
}

// a^(2^n): n successive squarings.
constexpr Element square_times(Element a, int n) noexcept {
  for (int i = 0; i < n; ++i) a = square(a);
  return a;
}

// The residue of a in [0, p). a < 2^256 = 2p + 38, so at most two
// subtractions of p.
constexpr Element canonical(Element a) noexcept {
  while (internal::greater_equal(a, kP)) a = internal::subtract_smaller(a, kP);
  return a;
}

constexpr bool equal(const Element& a, const Element& b) noexcept {
  const Element ca = canonical(a);
  const Element cb = canonical(b);
  for (int i = 0; i < 8; ++i) {
    if (ca.limb[i] != cb.limb[i]) return false;
  }
  return true;
}

constexpr bool is_zero(const Element& a) noexcept { return equal(a, kZero); }

// RFC 8032 §5.1.2/§5.1.3: x is "negative" when its residue in [0, p) is odd.
constexpr bool is_negative(const Element& a) noexcept { return (canonical(a).limb[0] & 1u) != 0; }

// Bits 0..254 of a 32-byte little-endian string (bit 255 is ignored: in a
// point encoding it is the sign of x). The value may be >= p: see
// is_canonical().
constexpr Element from_bytes(std::span<const std::uint8_t, 32> bytes) noexcept {
  Element r{};
  for (int i = 0; i < 8; ++i) {
    r.limb[i] = std::uint32_t{bytes[4 * i]} | (std::uint32_t{bytes[4 * i + 1]} << 8) |
                (std::uint32_t{bytes[4 * i + 2]} << 16) | (std::uint32_t{bytes[4 * i + 3]} << 24);
  }
  r.limb[7] &= 0x7fffffffu;
  return r;
}

// True if bits 0..254 of `bytes`, read as above, are below p (the unique
// encoding of their residue).
constexpr bool is_canonical(std::span<const std::uint8_t, 32> bytes) noexcept {
  return !internal::greater_equal(from_bytes(bytes), kP);
}

// The residue in [0, p) as 32 little-endian bytes (bit 255 is zero).
constexpr std::array<std::uint8_t, 32> to_bytes(const Element& a) noexcept {
  const Element c = canonical(a);
  std::array<std::uint8_t, 32> out{};
  for (int i = 0; i < 8; ++i) {
    for (int k = 0; k < 4; ++k) out[4 * i + k] = static_cast<std::uint8_t>(c.limb[i] >> (8 * k));
  }
  return out;
}

// a^(2^250 - 1), the common prefix of the exponents p - 2 and (p - 5) / 8,
// built from a^(2^n - 1) for n = 1, 2, 4, 5, 10, 20, 40, 50, 100, 200, 250
// (a^(2^(m+n) - 1) = (a^(2^m - 1))^(2^n) * a^(2^n - 1)).
constexpr Element pow_2_250_minus_1(const Element& a) noexcept {
  const Element e1 = a;
  const Element e2 = mul(square(e1), e1);
  const Element e4 = mul(square_times(e2, 2), e2);
  const Element e5 = mul(square(e4), e1);
  const Element e10 = mul(square_times(e5, 5), e5);
  const Element e20 = mul(square_times(e10, 10), e10);
  const Element e40 = mul(square_times(e20, 20), e20);
  const Element e50 = mul(square_times(e40, 10), e10);
  const Element e100 = mul(square_times(e50, 50), e50);
  const Element e200 = mul(square_times(e100, 100), e100);
  return mul(square_times(e200, 50), e50);
}

// 1/a = a^(p - 2) (Fermat); 0 for a = 0.
// p - 2 = 2^255 - 21 = (2^250 - 1) * 2^5 + 11.
constexpr Element invert(const Element& a) noexcept {
  const Element a2 = square(a);
  const Element a11 = mul(mul(square_times(a2, 2), a), a2);  // a^8 * a * a^2
  return mul(square_times(pow_2_250_minus_1(a), 5), a11);
}

// a^((p - 5) / 8), the exponent of RFC 8032 §5.1.3's square root.
// (p - 5) / 8 = 2^252 - 3 = (2^250 - 1) * 4 + 1.
constexpr Element pow_p_minus_5_over_8(const Element& a) noexcept {
  return mul(square_times(pow_2_250_minus_1(a), 2), a);
}

// d = -121665 / 121666, the curve constant (RFC 8032 §5.1), its double, and
// sqrt(-1) = 2^((p - 1) / 4); checked against their definitions in
// test/crypto/curve_test.cc.
inline constexpr Element kD = {
    {0x135978a3, 0x75eb4dca, 0x4141d8ab, 0x00700a4d, 0x7779e898, 0x8cc74079, 0x2b6ffe73, 0x52036cee}};
inline constexpr Element kTwoD = add(kD, kD);
inline constexpr Element kSqrtMinusOne = {
    {0x4a0ea0b0, 0xc4ee1b27, 0xad2fe478, 0x2f431806, 0x3dfbd7a7, 0x2b4d0099, 0x4fc1df0b, 0x2b832480}};

}  // namespace hadynet::crypto::gf25519

#endif  // HADYNET_FIRMWARE_CRYPTO_FIELD25519_H_
