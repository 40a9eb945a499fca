// The internals under ed25519_verify: the field constants against their
// definitions, field arithmetic identities on loosely reduced values,
// scalar reduction and NAF recoding (against libsodium and a reference
// sum), point decoding/encoding and [s]B + [k]P against libsodium's
// crypto_scalarmult_ed25519_base_noclamp and crypto_core_ed25519_add, and
// the small-order points.
#include <sodium.h>

#include "firmware/crypto/edwards25519.h"
#include "firmware/crypto/field25519.h"
#include "firmware/crypto/scalar25519.h"
#include "test/crypto/crypto_test_support.h"

namespace hadynet::crypto::test {
namespace {

namespace gf = gf25519;
namespace ed = edwards25519;
namespace sc = scalar25519;

// [s]B + [k]P through the table the verifier builds.
ed::Projective mul_add(const sc::Scalar& s, const sc::Scalar& k, const ed::Extended& p) {
  ed::PointMultiples p_multiples;
  ed::fill_odd_multiples(p_multiples, p);
  return ed::double_scalar_mul_base(s, k, p_multiples);
}

class Curve : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { init_sodium(); }
};

gf::Element small(std::uint32_t v) { return {{v, 0, 0, 0, 0, 0, 0, 0}}; }

// Any 256-bit value, also >= p (loosely reduced inputs are allowed).
gf::Element random_element(Rng& rng) {
  gf::Element e{};
  for (auto& l : e.limb) l = static_cast<std::uint32_t>(rng.next());
  return e;
}

sc::Scalar scalar_of(const Bytes32& b) {
  sc::Scalar s{};
  EXPECT_TRUE(sc::from_canonical_bytes(s, b)) << to_hex(b);
  return s;
}

TEST_F(Curve, FieldConstantsMatchTheirDefinitions) {
  // d * 121666 = -121665.
  EXPECT_TRUE(gf::equal(gf::mul(gf::kD, small(121666)), gf::neg(small(121665))));
  EXPECT_TRUE(gf::equal(gf::kTwoD, gf::add(gf::kD, gf::kD)));
  // sqrt(-1)^2 = -1.
  EXPECT_TRUE(gf::equal(gf::square(gf::kSqrtMinusOne), gf::neg(gf::kOne)));
  // B: y = 4/5, x even, on the curve -x^2 + y^2 = 1 + d x^2 y^2, T = xy.
  const ed::Extended& b = ed::kBasePoint;
  EXPECT_TRUE(gf::equal(gf::mul(b.y, small(5)), small(4)));
  EXPECT_FALSE(gf::is_negative(b.x));
  const gf::Element x2 = gf::square(b.x), y2 = gf::square(b.y);
  EXPECT_TRUE(gf::equal(gf::sub(y2, x2), gf::add(gf::kOne, gf::mul(gf::kD, gf::mul(x2, y2)))));
  EXPECT_TRUE(gf::equal(b.t, gf::mul(b.x, b.y)));
  // Its encoding, RFC 8032 §5.1: 0x5866...66.
  Bytes32 expected{};
  expected.fill(0x66);
  expected[0] = 0x58;
  EXPECT_EQ(ed::encode(b), expected);
}

TEST_F(Curve, FieldArithmeticIdentitiesHoldOnLooseValues) {
  Rng rng(0xf1e1'd001);
  // Edge values: 0, 1, p - 1, p, p + 1, 2p, 2^255 - 1, 2^256 - 38 .. 2^256 - 1.
  std::vector<gf::Element> values = {gf::kZero, gf::kOne, gf::sub(gf::kP, gf::kOne), gf::kP};
  gf::Element p1 = gf::kP;
  p1.limb[0] += 1;
  values.push_back(p1);
  gf::Element two_p = gf::kP;
  for (int i = 0; i < 8; ++i) two_p.limb[i] = (gf::kP.limb[i] << 1) | (i > 0 ? gf::kP.limb[i - 1] >> 31 : 0);
  values.push_back(two_p);
  gf::Element top{};
  for (auto& l : top.limb) l = 0xffffffff;
  values.push_back(top);
  for (std::uint32_t d = 1; d <= 38; d += 37) {
    gf::Element v = top;
    v.limb[0] -= d - 1;
    values.push_back(v);
  }
  for (int i = 0; i < 300; ++i) values.push_back(random_element(rng));

  for (std::size_t i = 0; i < values.size(); ++i) {
    const gf::Element& a = values[i];
    const gf::Element& b = values[(i * 7 + 3) % values.size()];
    const gf::Element& c = values[(i * 13 + 5) % values.size()];
    SCOPED_TRACE(i);
    // Canonical form: below p, same residue.
    const gf::Element ca = gf::canonical(a);
    EXPECT_FALSE(gf::internal::greater_equal(ca, gf::kP));
    EXPECT_TRUE(gf::equal(gf::sub(a, ca), gf::kZero));
    EXPECT_EQ(gf::to_bytes(a), gf::to_bytes(ca));
    // Ring identities.
    EXPECT_TRUE(gf::equal(gf::square(a), gf::mul(a, a)));
    EXPECT_TRUE(gf::equal(gf::sub(gf::add(a, b), b), a));
    EXPECT_TRUE(gf::equal(gf::add(gf::sub(a, b), b), a));
    EXPECT_TRUE(gf::equal(gf::add(a, gf::neg(a)), gf::kZero));
    EXPECT_TRUE(gf::equal(gf::mul(a, gf::add(b, c)), gf::add(gf::mul(a, b), gf::mul(a, c))));
    EXPECT_TRUE(gf::equal(gf::mul(gf::mul(a, b), c), gf::mul(a, gf::mul(b, c))));
    if (!gf::is_zero(a)) {
      EXPECT_TRUE(gf::equal(gf::mul(a, gf::invert(a)), gf::kOne));
    }
    // Bytes round trip of the canonical value.
    const Bytes32 bytes = gf::to_bytes(a);
    EXPECT_TRUE(gf::is_canonical(bytes));
    EXPECT_TRUE(gf::equal(gf::from_bytes(bytes), a));
  }
  EXPECT_TRUE(gf::is_zero(gf::invert(gf::kZero)));
  EXPECT_TRUE(gf::is_zero(gf::kP));
  EXPECT_TRUE(gf::is_zero(two_p));
}

TEST_F(Curve, CanonicalBytesAreExactlyThoseBelowP) {
  Bytes32 p_minus_1 = gf::to_bytes(gf::sub(gf::kP, gf::kOne));
  EXPECT_TRUE(gf::is_canonical(p_minus_1));
  for (unsigned extra = 0; extra < 19; ++extra) {
    Bytes32 b{};
    b.fill(0xff);
    b[0] = static_cast<std::uint8_t>(0xed + extra);
    b[31] = 0x7f;
    EXPECT_FALSE(gf::is_canonical(b)) << extra;
    b[31] = 0xff;  // the sign bit is ignored
    EXPECT_FALSE(gf::is_canonical(b)) << extra;
  }
  p_minus_1[31] |= 0x80;
  EXPECT_TRUE(gf::is_canonical(p_minus_1));
}

TEST_F(Curve, ScalarReductionMatchesLibsodium) {
  Rng rng(0x5ca1'0001);
  std::vector<Bytes64> inputs;
  Bytes64 zeros{}, ones{};
  ones.fill(0xff);
  inputs.push_back(zeros);
  inputs.push_back(ones);
  Bytes64 l_wide{};
  std::copy(order_l().begin(), order_l().end(), l_wide.begin());
  inputs.push_back(l_wide);  // L -> 0
  l_wide[0] -= 1;
  inputs.push_back(l_wide);  // L - 1
  for (int i = 0; i < 1000; ++i) inputs.push_back(rng.array<64>());
  for (const Bytes64& in : inputs) {
    EXPECT_EQ(sc::to_bytes(sc::reduce_wide(in)), sodium_reduce(in)) << to_hex(in);
  }
}

TEST_F(Curve, CanonicalScalarsAreExactlyThoseBelowL) {
  sc::Scalar s{};
  Bytes32 b = order_l();
  EXPECT_FALSE(sc::from_canonical_bytes(s, b));
  b[0] -= 1;
  EXPECT_TRUE(sc::from_canonical_bytes(s, b));
  EXPECT_EQ(sc::to_bytes(s), b);
  b = order_l();
  b[0] += 1;
  EXPECT_FALSE(sc::from_canonical_bytes(s, b));
  b.fill(0xff);
  EXPECT_FALSE(sc::from_canonical_bytes(s, b));
  b.fill(0);
  b[31] = 0x10;  // 2^252 < L
  EXPECT_TRUE(sc::from_canonical_bytes(s, b));
  b[31] = 0x20;  // 2^253 > L
  EXPECT_FALSE(sc::from_canonical_bytes(s, b));
}

TEST_F(Curve, NafDigitsSumToTheScalarAndAreSparse) {
  Rng rng(0x5ca1'0002);
  std::vector<Bytes32> scalars = {Bytes32{}, order_l()};
  scalars[1][0] -= 1;  // L - 1
  Bytes32 pattern{};
  pattern.fill(0xff);
  pattern[31] = 0x0f;  // 2^252 - 1
  scalars.push_back(pattern);
  for (int i = 0; i < 200; ++i) scalars.push_back(sodium_reduce(rng.array<64>()));
  for (int width = 2; width <= 7; ++width) {
    SCOPED_TRACE(width);
    const int max_digit = (1 << (width - 1)) - 1;
    for (const Bytes32& b : scalars) {
      std::int8_t digits[sc::kNafDigits];
      sc::naf(digits, scalar_of(b), width);
      // Sum digits[i] 2^i in 32-bit limbs of signed 64-bit accumulators.
      std::int64_t acc[9] = {};
      int last_nonzero = -100;
      for (int i = 0; i < static_cast<int>(sc::kNafDigits); ++i) {
        const int d = digits[i];
        if (d == 0) continue;
        EXPECT_TRUE(d % 2 != 0 && d >= -max_digit && d <= max_digit) << d;
        EXPECT_GE(i - last_nonzero, width) << "digits " << last_nonzero << ", " << i;
        EXPECT_LE(i, 253);
        last_nonzero = i;
        acc[i / 32] += static_cast<std::int64_t>(d) * (std::int64_t{1} << (i % 32));
      }
      Bytes32 sum{};
      std::int64_t carry = 0;
      for (int l = 0; l < 8; ++l) {
        const std::int64_t v = acc[l] + carry;
        const std::uint32_t limb = static_cast<std::uint32_t>(v);
        carry = (v - static_cast<std::int64_t>(limb)) / (std::int64_t{1} << 32);
        for (int k = 0; k < 4; ++k) sum[4 * l + k] = static_cast<std::uint8_t>(limb >> (8 * k));
      }
      EXPECT_EQ(carry + acc[8], 0);
      EXPECT_EQ(sum, b);
    }
  }
}

TEST_F(Curve, BaseMultiplesMatchLibsodium) {
  Rng rng(0x5ca1'0003);
  for (int i = 0; i < 150; ++i) {
    Bytes32 s = sodium_reduce(rng.array<64>());
    if (i == 0) {
      s = order_l();
      s[0] -= 1;  // [L - 1]B = -B
    } else if (i == 1) {
      s = Bytes32{};
      s[0] = 1;
    }
    const Bytes32 expected = sodium_base_mul(s);
    // [s]B + [0]P for P = identity and for P = B.
    EXPECT_EQ(ed::encode(mul_add(scalar_of(s), sc::Scalar{}, ed::kIdentity)), expected);
    EXPECT_EQ(ed::encode(mul_add(scalar_of(s), sc::Scalar{}, ed::kBasePoint)), expected);
    // [0]B + [s]B.
    EXPECT_EQ(ed::encode(mul_add(sc::Scalar{}, scalar_of(s), ed::kBasePoint)), expected);
  }
}

TEST_F(Curve, DoubleScalarMultiplicationMatchesLibsodium) {
  // [s]B + [k]P with P = [t]B is [s + k t]B; and with P = [t]B + T
  // (torsion) it is [s + k t]B + [k]T.
  Rng rng(0x5ca1'0004);
  const auto& torsion = torsion_multiples();
  for (int i = 0; i < 150; ++i) {
    const Bytes32 s = sodium_reduce(rng.array<64>());
    const Bytes32 k = sodium_reduce(rng.array<64>());
    const Bytes32 t = sodium_reduce(rng.array<64>());
    const Bytes32 p_bytes = sodium_base_mul(t);
    ed::Extended p;
    ASSERT_TRUE(ed::decode(p, p_bytes));
    EXPECT_EQ(ed::encode(p), p_bytes);
    const Bytes32 expected = sodium_base_mul(sodium_scalar_add(s, sodium_scalar_mul(k, t)));
    EXPECT_EQ(ed::encode(mul_add(scalar_of(s), scalar_of(k), p)), expected);

    Bytes32 mixed_bytes{};
    ASSERT_EQ(crypto_core_ed25519_add(mixed_bytes.data(), p_bytes.data(), torsion[1].data()), 0);
    ed::Extended mixed;
    ASSERT_TRUE(ed::decode(mixed, mixed_bytes));
    Bytes32 expected_mixed{};
    ASSERT_EQ(crypto_core_ed25519_add(expected_mixed.data(), expected.data(), torsion[k[0] & 7u].data()), 0);
    EXPECT_EQ(ed::encode(mul_add(scalar_of(s), scalar_of(k), mixed)), expected_mixed);
  }
}

TEST_F(Curve, SmallOrderPointsHaveTheirOrders) {
  const auto& torsion = torsion_multiples();
  // The list is [j]T by libsodium's addition.
  for (std::size_t j = 0; j + 1 < 8; ++j) {
    Bytes32 next{};
    ASSERT_EQ(crypto_core_ed25519_add(next.data(), torsion[j].data(), torsion[1].data()), 0);
    EXPECT_EQ(next, torsion[j + 1]) << j;
  }
  const std::size_t orders[8] = {1, 8, 4, 8, 2, 8, 4, 8};
  for (std::size_t j = 0; j < 8; ++j) {
    SCOPED_TRACE(j);
    ed::Extended p;
    ASSERT_TRUE(ed::decode(p, torsion[j]));
    EXPECT_EQ(ed::encode(p), torsion[j]);
    EXPECT_TRUE(ed::has_small_order_y(torsion[j]));
    // [order]P = O and, for order > 1, [order / 2]P != O.
    const sc::Scalar order = {{static_cast<std::uint32_t>(orders[j]), 0, 0, 0, 0, 0, 0, 0}};
    const Bytes32 identity = torsion[0];
    EXPECT_EQ(ed::encode(mul_add(sc::Scalar{}, order, p)), identity);
    if (orders[j] > 1) {
      const sc::Scalar half = {{static_cast<std::uint32_t>(orders[j] / 2), 0, 0, 0, 0, 0, 0, 0}};
      EXPECT_NE(ed::encode(mul_add(sc::Scalar{}, half, p)), identity);
    }
  }
}

TEST_F(Curve, SmallOrderYIsRecognisedWithoutDecoding) {
  // Sign-bit variants and the non-canonical 0 and 1 count; ordinary points
  // do not.
  for (const char* hex : {"0100000000000000000000000000000000000000000000000000000000000080",
                          "ecffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff",
                          "edffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff7f",
                          "eeffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff"}) {
    EXPECT_TRUE(ed::has_small_order_y(array_from_hex<32>(hex))) << hex;
  }
  Rng rng(0x5ca1'0005);
  for (int i = 0; i < 50; ++i) {
    const Bytes32 p = sodium_base_mul(sodium_reduce(rng.array<64>()));
    EXPECT_FALSE(ed::has_small_order_y(p)) << to_hex(p);
  }
  Bytes32 two{};
  two[0] = 2;
  EXPECT_FALSE(ed::has_small_order_y(two));
}

TEST_F(Curve, DecodingFollowsRfc8032) {
  Rng rng(0x5ca1'0006);
  // Points from libsodium round-trip, and their negations (sign bit flipped)
  // decode to -P.
  for (int i = 0; i < 100; ++i) {
    const Bytes32 bytes = sodium_base_mul(sodium_reduce(rng.array<64>()));
    ed::Extended p;
    ASSERT_TRUE(ed::decode(p, bytes));
    EXPECT_EQ(ed::encode(p), bytes);
    Bytes32 negated = bytes;
    negated[31] ^= 0x80;
    ed::Extended q;
    ASSERT_TRUE(ed::decode(q, negated));
    EXPECT_EQ(ed::encode(ed::negate(p)), negated);
  }
  // x = 0 with the sign bit set (y = 1, y = -1) is refused.
  ed::Extended p;
  EXPECT_FALSE(ed::decode(p, array_from_hex<32>("0100000000000000000000000000000000000000000000000000000000000080")));
  EXPECT_FALSE(ed::decode(p, array_from_hex<32>("ecffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff")));
  // y >= p is refused even where y - p would decode (y = p + 1).
  EXPECT_FALSE(ed::decode(p, array_from_hex<32>("eeffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff7f")));
}

}  // namespace
}  // namespace hadynet::crypto::test
