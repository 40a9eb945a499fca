#include "firmware/crypto/edwards25519.h"

namespace hadynet::crypto::edwards25519 {
namespace {

using scalar25519::kNafDigits;
using scalar25519::Scalar;

// The odd multiples of B for NAF digits of width kBaseWindow: B, 3B, ...,
// 31B, computed by the compiler from kBasePoint (flash, 2 KiB).
constexpr std::size_t kBaseTableSize = std::size_t{1} << (kBaseWindow - 2);
constexpr std::array<Cached, kBaseTableSize> kBaseOddMultiples = [] {
  std::array<Cached, kBaseTableSize> table{};
  fill_odd_multiples(table, kBasePoint);
  return table;
}();

// The y of the four points of order 8 is +-y8: 2P has order 4, so
// y(2P) = (x^2 + y^2) / (2 + x^2 - y^2) = 0, and with the curve equation
// d y^4 + 2 y^2 - 1 = 0. Checked in test/crypto/curve_test.cc ([4]P != O,
// [8]P = O for the points with this y).
constexpr Element kOrder8Y = {
    {0x8f95e826, 0xb027b2c2, 0x89f4c345, 0xf098eff2, 0x05acdfd5, 0x3933c6d3, 0x880238b1, 0x05fc536d}};

// c + digit * P, from table[i] = (2i + 1)P; c itself for digit 0.
Completed add_digit(const Completed& c, std::int8_t digit, std::span<const Cached> table) noexcept {
  if (digit == 0) return c;
  const Extended e = to_extended(c);
  return digit > 0 ? add(e, table[static_cast<std::size_t>(digit / 2)])
                   : subtract(e, table[static_cast<std::size_t>(-digit / 2)]);
}

}  // namespace

bool decode(Extended& out, std::span<const std::uint8_t, 32> bytes) noexcept {
  using namespace gf25519;
  if (!is_canonical(bytes)) return false;
  const Element y = from_bytes(bytes);
  const bool x_negative = (bytes[31] & 0x80u) != 0;
  // x^2 = u / v with u = y^2 - 1, v = d y^2 + 1 (v is never 0: -1/d is not a
  // square). Candidate root x = u v^3 (u v^7)^((p - 5) / 8): then v x^2 is u
  // (x is a root), -u (x sqrt(-1) is), or neither (u / v is no square).
  const Element y2 = square(y);
  const Element u = sub(y2, kOne);
  const Element v = add(mul(kD, y2), kOne);
  const Element v3 = mul(square(v), v);
  const Element v7 = mul(square(v3), v);
  Element x = mul(mul(u, v3), pow_p_minus_5_over_8(mul(u, v7)));
  const Element vx2 = mul(v, square(x));
  if (!equal(vx2, u)) {
    if (!equal(vx2, neg(u))) return false;
    x = mul(x, kSqrtMinusOne);
  }
  if (is_zero(x) && x_negative) return false;
  if (is_negative(x) != x_negative) x = neg(x);
  out = {x, y, kOne, mul(x, y)};
  return true;
}

std::array<std::uint8_t, 32> encode(const Projective& p) noexcept {
  using namespace gf25519;
  const Element z_inverse = invert(p.z);
  std::array<std::uint8_t, 32> out = to_bytes(mul(p.y, z_inverse));
  if (is_negative(mul(p.x, z_inverse))) out[31] |= 0x80u;
  return out;
}

std::array<std::uint8_t, 32> encode(const Extended& p) noexcept { return encode(Projective{p.x, p.y, p.z}); }

bool has_small_order_y(std::span<const std::uint8_t, 32> bytes) noexcept {
  using namespace gf25519;
  const Element y = from_bytes(bytes);
  return equal(y, kOne) || equal(y, neg(kOne)) || is_zero(y) || equal(y, kOrder8Y) || equal(y, neg(kOrder8Y));
}

Projective double_scalar_mul_base(const Scalar& s, const Scalar& k, const PointMultiples& p_multiples) noexcept {
  std::int8_t s_digits[kNafDigits];
  std::int8_t k_digits[kNafDigits];
  scalar25519::naf(s_digits, s, kBaseWindow);
  scalar25519::naf(k_digits, k, kPointWindow);

  int top = static_cast<int>(kNafDigits) - 1;
  while (top >= 0 && s_digits[top] == 0 && k_digits[top] == 0) --top;

  // Left to right: double, then add the digits' multiples of B and P.
  Projective acc = {gf25519::kZero, gf25519::kOne, gf25519::kOne};
  for (int i = top; i >= 0; --i) {
    Completed c = dbl(acc);
    c = add_digit(c, s_digits[i], kBaseOddMultiples);
    c = add_digit(c, k_digits[i], p_multiples);
    acc = to_projective(c);
  }
  return acc;
}

}  // namespace hadynet::crypto::edwards25519
