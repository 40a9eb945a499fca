// The group of edwards25519 (RFC 8032 §5.1): -x^2 + y^2 = 1 + d x^2 y^2 over
// GF(2^255 - 19), the base point B and point encoding, for Ed25519
// verification. Variable time (public data only).
//
// Point representations (Hisil, Wong, Carter, Dawson 2008; the formulas of
// RFC 8032 §5.1.4):
//   Extended   (X : Y : Z : T), x = X/Z, y = Y/Z, x*y = T/Z.
//   Projective (X : Y : Z) alone: enough to double.
//   Cached     a point prepared as an addend: (Y + X, Y - X, 2Z, 2dT).
//   Completed  (E, F, G, H), the result of an addition or doubling before
//              its last products: X = EF, Y = GH, Z = FG, T = EH.
// The addition and doubling formulas are complete on this curve (a = -1 is a
// square and d is not), so they hold for every pair of points, the identity
// and the points of small order included.
#ifndef HADYNET_FIRMWARE_CRYPTO_EDWARDS25519_H_
#define HADYNET_FIRMWARE_CRYPTO_EDWARDS25519_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/crypto/field25519.h"
#include "firmware/crypto/scalar25519.h"

namespace hadynet::crypto::edwards25519 {

using gf25519::Element;

struct Extended {
  Element x, y, z, t;
};
struct Projective {
  Element x, y, z;
};
struct Cached {
  Element y_plus_x, y_minus_x, two_z, two_d_t;
};
struct Completed {
  Element e, f, g, h;
};

inline constexpr Extended kIdentity = {gf25519::kZero, gf25519::kOne, gf25519::kOne, gf25519::kZero};

// The base point B = (x, 4/5) with x "positive" (even), RFC 8032 §5.1;
// checked against its definition in test/crypto/curve_test.cc.
inline constexpr Extended kBasePoint = [] {
  const Element x = {{0x8f25d51a, 0xc9562d60, 0x9525a7b2, 0x692cc760, 0xfdd6dc5c, 0xc0a4e231, 0xcd6e53fe, 0x216936d3}};
  const Element y = {{0x66666658, 0x66666666, 0x66666666, 0x66666666, 0x66666666, 0x66666666, 0x66666666, 0x66666666}};
  return Extended{x, y, gf25519::kOne, gf25519::mul(x, y)};
}();

// Doubling (RFC 8032 §5.1.4): A = X^2, B = Y^2, C = 2Z^2, H = A + B,
// E = H - (X + Y)^2, G = A - B, F = C + G. Uses X, Y, Z only.
constexpr Completed dbl(const Element& x, const Element& y, const Element& z) noexcept {
  using namespace gf25519;
  const Element a = square(x);
  const Element b = square(y);
  const Element z2 = square(z);
  const Element c = add(z2, z2);
  const Element h = add(a, b);
  const Element e = sub(h, square(add(x, y)));
  const Element g = sub(a, b);
  const Element f = add(c, g);
  return {e, f, g, h};
}
constexpr Completed dbl(const Projective& p) noexcept { return dbl(p.x, p.y, p.z); }
constexpr Completed dbl(const Extended& p) noexcept { return dbl(p.x, p.y, p.z); }

// p + q (RFC 8032 §5.1.4): A = (Y1 - X1)(Y2 - X2), B = (Y1 + X1)(Y2 + X2),
// C = T1 2d T2, D = Z1 2 Z2, E = B - A, F = D - C, G = D + C, H = B + A.
constexpr Completed add(const Extended& p, const Cached& q) noexcept {
  using namespace gf25519;
  const Element a = mul(sub(p.y, p.x), q.y_minus_x);
  const Element b = mul(add(p.y, p.x), q.y_plus_x);
  const Element c = mul(p.t, q.two_d_t);
  const Element d = mul(p.z, q.two_z);
  return {sub(b, a), sub(d, c), add(d, c), add(b, a)};
}

// p - q: the addition with -q = (-x, y), i.e. Y + X and Y - X swapped and
// T negated.
constexpr Completed subtract(const Extended& p, const Cached& q) noexcept {
  using namespace gf25519;
  const Element a = mul(sub(p.y, p.x), q.y_plus_x);
  const Element b = mul(add(p.y, p.x), q.y_minus_x);
  const Element c = mul(p.t, q.two_d_t);
  const Element d = mul(p.z, q.two_z);
  return {sub(b, a), add(d, c), sub(d, c), add(b, a)};
}

constexpr Extended to_extended(const Completed& c) noexcept {
  using gf25519::mul;
  return {mul(c.e, c.f), mul(c.g, c.h), mul(c.f, c.g), mul(c.e, c.h)};
}

constexpr Projective to_projective(const Completed& c) noexcept {
  using gf25519::mul;
  return {mul(c.e, c.f), mul(c.g, c.h), mul(c.f, c.g)};
}

constexpr Cached to_cached(const Extended& p) noexcept {
  using namespace gf25519;
  return {add(p.y, p.x), sub(p.y, p.x), add(p.z, p.z), mul(p.t, kTwoD)};
}

constexpr Extended negate(const Extended& p) noexcept {
  return {gf25519::neg(p.x), p.y, p.z, gf25519::neg(p.t)};
}

// P, 3P, 5P, ...: table[i] = (2i + 1)P for every entry, the odd multiples
// the NAF digits of width w select (a table of 2^(w-2) entries, >= 1).
constexpr void fill_odd_multiples(std::span<Cached> table, const Extended& p) noexcept {
  const Cached two_p = to_cached(to_extended(dbl(p)));
  Extended multiple = p;
  table[0] = to_cached(multiple);
  for (std::size_t i = 1; i < table.size(); ++i) {
    multiple = to_extended(add(multiple, two_p));
    table[i] = to_cached(multiple);
  }
}

// Decodes a point (RFC 8032 §5.1.3): y from bits 0..254, the sign of x from
// bit 255. Fails (returns false, `out` unspecified) if y >= p, if
// (y^2 - 1) / (d y^2 + 1) has no square root, or if x = 0 with the sign bit
// set. Accepts every other point, those of small order included.
bool decode(Extended& out, std::span<const std::uint8_t, 32> bytes) noexcept;

// Encodes a point (RFC 8032 §5.1.2): y as 32 little-endian bytes in [0, p),
// the parity of x in bit 255. The only encoding this produces is canonical.
std::array<std::uint8_t, 32> encode(const Projective& p) noexcept;
std::array<std::uint8_t, 32> encode(const Extended& p) noexcept;

// True if `bytes`, whatever its sign bit, names a y of one of the eight
// points of order 1, 2, 4 or 8: y = 1 (identity), -1 (order 2), 0 (order
// 4), or +-y8 (order 8), y read mod p (so the non-canonical p and p + 1 also
// count). Needs no decoding; bytes that are no point at all may match too.
bool has_small_order_y(std::span<const std::uint8_t, 32> bytes) noexcept;

// [s]B + [k]P for s, k < L: one shared chain of doublings, s as a width-6
// NAF over a compile-time table of B's odd multiples (16 entries, flash),
// k as a width-4 NAF over P's odd multiples (4 entries), which the caller
// fills with fill_odd_multiples(): kept in the caller's frame, the table
// and the filling's temporaries are never on the stack together with the
// NAF digits. P may be any point (of small or mixed order too).
inline constexpr int kBaseWindow = 6;
inline constexpr int kPointWindow = 4;
using PointMultiples = std::array<Cached, std::size_t{1} << (kPointWindow - 2)>;
Projective double_scalar_mul_base(const scalar25519::Scalar& s, const scalar25519::Scalar& k,
                                  const PointMultiples& p_multiples) noexcept;

}  // namespace hadynet::crypto::edwards25519

#endif  // HADYNET_FIRMWARE_CRYPTO_EDWARDS25519_H_
