// Crafted signatures at the edges of the acceptance rules, each compared
// with libsodium's crypto_sign_verify_detached (exact agreement). The
// points and scalars are built with libsodium's own core API
// (crypto_core_ed25519_*, crypto_scalarmult_ed25519_base_noclamp), not with
// the code under test. Where a rule, not the equation, must be what
// refuses a signature, the test also shows that the cofactorless equation
// itself holds (with the internal edwards25519/scalar25519 functions), so
// a verifier without the rule would have accepted.
#include <sodium.h>

#include <string>

#include "firmware/crypto/ed25519_verify.h"
#include "firmware/crypto/edwards25519.h"
#include "firmware/crypto/scalar25519.h"
#include "test/crypto/crypto_test_support.h"

namespace hadynet::crypto::test {
namespace {

namespace ed = edwards25519;
namespace sc = scalar25519;

// [s]B + [k]P through the table the verifier builds.
ed::Projective mul_add(const sc::Scalar& s, const sc::Scalar& k, const ed::Extended& p) {
  ed::PointMultiples p_multiples;
  ed::fill_odd_multiples(p_multiples, p);
  return ed::double_scalar_mul_base(s, k, p_multiples);
}

class Ed25519Crafted : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { init_sodium(); }
};

// Both verdicts, which must agree; returns ours.
bool verdict(const Bytes64& sig, std::span<const std::uint8_t> message, const Bytes32& pk,
             const std::string& what) {
  const bool ours = ed25519_verify(sig, message, pk);
  const bool theirs = sodium_verify(sig, message, pk);
  EXPECT_EQ(ours, theirs) << what << "\n  sig " << to_hex(sig) << "\n  pk " << to_hex(pk);
  return ours;
}

// True if encode([S mod L]B - [k]A) == R for k = SHA-512(R || A || M) mod L:
// the cofactorless equation alone, without the acceptance rules. A must
// decode.
bool equation_holds(const Bytes64& sig, std::span<const std::uint8_t> message, const Bytes32& pk) {
  Bytes32 r{}, s_bytes{};
  std::copy_n(sig.begin(), 32, r.begin());
  std::copy_n(sig.begin() + 32, 32, s_bytes.begin());
  Bytes64 wide{};
  std::copy(s_bytes.begin(), s_bytes.end(), wide.begin());
  const sc::Scalar s = sc::reduce_wide(wide);
  const Bytes32 k_bytes = sodium_challenge(r, pk, message);
  Bytes64 k_wide{};
  std::copy(k_bytes.begin(), k_bytes.end(), k_wide.begin());
  const sc::Scalar k = sc::reduce_wide(k_wide);
  ed::Extended a;
  EXPECT_TRUE(ed::decode(a, pk)) << to_hex(pk);
  return ed::encode(mul_add(s, k, ed::negate(a))) == r;
}

Bytes32 random_scalar(Rng& rng) {
  const Bytes64 wide = rng.array<64>();
  return sodium_reduce(wide);
}

Bytes32 point_add(const Bytes32& p, const Bytes32& q) {
  Bytes32 r{};
  EXPECT_EQ(crypto_core_ed25519_add(r.data(), p.data(), q.data()), 0);
  return r;
}

// A signature by secret scalar a for public key bytes `pk` (which may carry a
// torsion component the secret does not know of), with nonce point R given
// and S = r + k a, k = SHA-512(R || pk || M) mod L.
Bytes64 sign_with(const Bytes32& a, const Bytes32& pk, const Bytes32& r, const Bytes32& big_r,
                  std::span<const std::uint8_t> message) {
  const Bytes32 k = sodium_challenge(big_r, pk, message);
  return join(big_r, sodium_scalar_add(r, sodium_scalar_mul(k, a)));
}

unsigned k_mod_8(const Bytes32& big_r, const Bytes32& pk, std::span<const std::uint8_t> message) {
  return sodium_challenge(big_r, pk, message)[0] & 7u;
}

Bytes counter_message(unsigned n) {
  const std::string s = "message " + std::to_string(n);
  return Bytes(s.begin(), s.end());
}

TEST_F(Ed25519Crafted, NonCanonicalSIsRejectedLikeLibsodium) {
  Rng rng(0xc0de'0001);
  for (int n = 0; n < 40; ++n) {
    const Bytes32 seed = rng.array<32>();
    Bytes32 pk{};
    std::array<std::uint8_t, crypto_sign_SECRETKEYBYTES> sk{};
    ASSERT_EQ(crypto_sign_seed_keypair(pk.data(), sk.data(), seed.data()), 0);
    const Bytes message = rng.bytes(rng.below(100));
    Bytes64 sig{};
    ASSERT_EQ(crypto_sign_detached(sig.data(), nullptr, message.data(), message.size(), sk.data()), 0);
    ASSERT_TRUE(verdict(sig, message, pk, "valid"));

    Bytes32 r{}, s{};
    std::copy_n(sig.begin(), 32, r.begin());
    std::copy_n(sig.begin() + 32, 32, s.begin());
    // S + L < 2^254: the same residue, so the equation still holds; only
    // rule 1 refuses it.
    const Bytes64 s_plus_l = join(r, add_256(s, order_l()));
    EXPECT_TRUE(equation_holds(s_plus_l, message, pk));
    EXPECT_FALSE(verdict(s_plus_l, message, pk, "S + L"));
    // S + 2L, S + 3L, ... up to what fits in 256 bits.
    Bytes32 s_big = add_256(s, order_l());
    for (int m = 2; m <= 15; ++m) {
      s_big = add_256(s_big, order_l());
      EXPECT_FALSE(verdict(join(r, s_big), message, pk, "S + mL"));
    }
  }
  // Fixed S values around L with a valid-looking R and key.
  const Bytes32 pk = array_from_hex<32>("d75a980182b10ab7d54bfed3c964073a0ee172f3daa62325af021a68f707511a");
  const Bytes32 r = array_from_hex<32>("e5564300c360ac729086e2cc806e828a84877f1eb8e5d974d873e06522490155");
  Bytes32 l_minus_1 = order_l();
  l_minus_1[0] -= 1;
  Bytes32 l_plus_1 = order_l();
  l_plus_1[0] += 1;
  Bytes32 all_ones{};
  all_ones.fill(0xff);
  Bytes32 two_252{};
  two_252[31] = 0x10;
  for (const Bytes32& s : {l_minus_1, order_l(), l_plus_1, all_ones, two_252}) {
    EXPECT_FALSE(verdict(join(r, s), {}, pk, "S = " + to_hex(s)));
  }
}

TEST_F(Ed25519Crafted, SmallOrderPublicKeysAreRejectedLikeLibsodium) {
  // For A of order dividing 8, [k]A = O whenever k = 0 mod 8, so R = [S]B
  // satisfies the cofactorless equation: a forgery for any S. Rule 3 must
  // refuse it.
  Rng rng(0xc0de'0002);
  for (std::size_t j = 0; j < 8; ++j) {
    const Bytes32& pk = torsion_multiples()[j];
    int forgeries = 0;
    for (unsigned n = 0; forgeries < 3 && n < 400; ++n) {
      const Bytes32 s = random_scalar(rng);
      const Bytes32 big_r = sodium_base_mul(s);
      const Bytes message = counter_message(n);
      if (k_mod_8(big_r, pk, message) != 0) continue;
      const Bytes64 sig = join(big_r, s);
      EXPECT_TRUE(equation_holds(sig, message, pk)) << "[" << j << "]T";
      EXPECT_FALSE(verdict(sig, message, pk, "small-order key [" + std::to_string(j) + "]T"));
      ++forgeries;
    }
    EXPECT_EQ(forgeries, 3) << "[" << j << "]T";
  }
  // Other encodings of small-order points: the sign bit set on x = 0 (y = 1,
  // y = -1) and the non-canonical y = p, p + 1 (= 0, 1) with either sign
  // (p + y for the other small-order y does not fit in 255 bits).
  const Bytes32 s = random_scalar(rng);
  const Bytes64 sig = join(sodium_base_mul(s), s);
  const char* encodings[] = {
      "0100000000000000000000000000000000000000000000000000000000000080",
      "ecffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff",
      "edffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff7f",
      "edffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff",
      "eeffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff7f",
      "eeffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff",
  };
  for (const char* hex : encodings) {
    for (unsigned n = 0; n < 8; ++n) EXPECT_FALSE(verdict(sig, counter_message(n), array_from_hex<32>(hex), hex));
  }
}

TEST_F(Ed25519Crafted, SmallOrderRIsRejectedLikeLibsodium) {
  // A' = [a]B + T (mixed order: not refused by rule 3). With S = k a,
  // [S]B - [k]A' = -[k]T, a point of small order. Search messages for which
  // R = -[k]T with k = SHA-512(R || A' || M): the equation holds exactly and
  // only rule 2 (R of small order) refuses it.
  Rng rng(0xc0de'0003);
  const auto& torsion = torsion_multiples();
  const Bytes32 a = random_scalar(rng);
  const Bytes32 pk = point_add(sodium_base_mul(a), torsion[1]);
  int found[8] = {};
  for (unsigned n = 0; n < 400; ++n) {
    const Bytes message = counter_message(n);
    for (unsigned j = 0; j < 8; ++j) {
      const Bytes32& big_r = torsion[j];
      const Bytes32 k = sodium_challenge(big_r, pk, message);
      if ((8 - (k[0] & 7u)) % 8 != j) continue;
      const Bytes64 sig = join(big_r, sodium_scalar_mul(k, a));
      EXPECT_TRUE(equation_holds(sig, message, pk)) << "R = [" << j << "]T";
      EXPECT_FALSE(verdict(sig, message, pk, "small-order R [" + std::to_string(j) + "]T"));
      ++found[j];
    }
  }
  for (unsigned j = 0; j < 8; ++j) EXPECT_GT(found[j], 0) << "no message found for R = [" << j << "]T";
  // The same small-order R values with a prime-order key (the equation
  // cannot hold), and the non-canonical small-order y (p, p + 1) and
  // sign-bit variants: refused by both.
  const Bytes32 prime_order_pk = sodium_base_mul(a);
  const Bytes32 s = random_scalar(rng);
  std::vector<Bytes32> rs(torsion.begin(), torsion.end());
  for (const char* hex : {"0100000000000000000000000000000000000000000000000000000000000080",
                          "edffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff7f",
                          "eeffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff"}) {
    rs.push_back(array_from_hex<32>(hex));
  }
  for (const Bytes32& big_r : rs) {
    EXPECT_FALSE(verdict(join(big_r, s), counter_message(0), prime_order_pk, "R " + to_hex(big_r)));
    EXPECT_FALSE(verdict(join(big_r, s), counter_message(0), pk, "R " + to_hex(big_r)));
  }
}

TEST_F(Ed25519Crafted, MixedOrderPublicKeyIsVerifiedCofactorlessLikeLibsodium) {
  // A' = [a]B + T, signed honestly with a: [S]B - [k]A' = R - [k]T, so the
  // cofactorless check accepts exactly when k = 0 mod 8 (a cofactored one
  // would accept always).
  Rng rng(0xc0de'0004);
  const Bytes32 a = random_scalar(rng);
  const Bytes32 pk = point_add(sodium_base_mul(a), torsion_multiples()[1]);
  int accepted = 0;
  const int kMessages = 200;
  for (int n = 0; n < kMessages; ++n) {
    const Bytes message = rng.bytes(rng.below(64));
    const Bytes32 r = random_scalar(rng);
    const Bytes32 big_r = sodium_base_mul(r);
    const Bytes64 sig = sign_with(a, pk, r, big_r, message);
    const bool ok = verdict(sig, message, pk, "mixed-order key");
    EXPECT_EQ(ok, k_mod_8(big_r, pk, message) == 0);
    accepted += ok ? 1 : 0;
  }
  EXPECT_GT(accepted, 0);
  EXPECT_LT(accepted, kMessages);
}

TEST_F(Ed25519Crafted, TorsionInRIsVerifiedCofactorlessLikeLibsodium) {
  // R' = [r]B + T (mixed order, not refused by rule 2). With a prime-order
  // key the equation gives [r]B != R': refused. With A' = [a]B + T it gives
  // [r]B - [k]T, equal to R' exactly when k = -1 mod 8: accepted then.
  Rng rng(0xc0de'0005);
  const auto& torsion = torsion_multiples();
  const Bytes32 a = random_scalar(rng);
  const Bytes32 prime_pk = sodium_base_mul(a);
  const Bytes32 mixed_pk = point_add(prime_pk, torsion[1]);
  int accepted = 0;
  const int kMessages = 200;
  for (int n = 0; n < kMessages; ++n) {
    const Bytes message = rng.bytes(rng.below(64));
    const Bytes32 r = random_scalar(rng);
    const Bytes32 big_r = point_add(sodium_base_mul(r), torsion[1]);
    EXPECT_FALSE(verdict(sign_with(a, prime_pk, r, big_r, message), message, prime_pk, "R with torsion"));
    const bool ok = verdict(sign_with(a, mixed_pk, r, big_r, message), message, mixed_pk, "R and A with torsion");
    EXPECT_EQ(ok, k_mod_8(big_r, mixed_pk, message) == 7);
    accepted += ok ? 1 : 0;
  }
  EXPECT_GT(accepted, 0);
  EXPECT_LT(accepted, kMessages);
}

TEST_F(Ed25519Crafted, NonCanonicalEncodingsAreRejectedLikeLibsodium) {
  // Every y in [p, 2^255) (p + 0 .. p + 18), both sign bits, as the public
  // key and as R, against a valid signature's other parts.
  Rng rng(0xc0de'0006);
  const Bytes32 seed = rng.array<32>();
  Bytes32 pk{};
  std::array<std::uint8_t, crypto_sign_SECRETKEYBYTES> sk{};
  ASSERT_EQ(crypto_sign_seed_keypair(pk.data(), sk.data(), seed.data()), 0);
  const Bytes message = rng.bytes(40);
  Bytes64 sig{};
  ASSERT_EQ(crypto_sign_detached(sig.data(), nullptr, message.data(), message.size(), sk.data()), 0);
  ASSERT_TRUE(verdict(sig, message, pk, "valid"));
  int decodable = 0;
  for (unsigned extra = 0; extra < 19; ++extra) {
    for (std::uint8_t sign : {std::uint8_t{0}, std::uint8_t{0x80}}) {
      Bytes32 y{};
      y.fill(0xff);
      y[0] = static_cast<std::uint8_t>(0xed + extra);
      y[31] = static_cast<std::uint8_t>(0x7f | sign);
      // Would the residue y - p decode? (Then only the canonicity rule
      // refuses the key.)
      Bytes32 reduced{};
      reduced[0] = static_cast<std::uint8_t>(extra);
      reduced[31] = sign;
      ed::Extended point;
      decodable += ed::decode(point, reduced) ? 1 : 0;
      EXPECT_FALSE(verdict(sig, message, y, "public key y = p + " + std::to_string(extra)));
      Bytes64 with_r = sig;
      std::copy(y.begin(), y.end(), with_r.begin());
      EXPECT_FALSE(verdict(with_r, message, pk, "R y = p + " + std::to_string(extra)));
    }
  }
  EXPECT_GT(decodable, 0);
}

TEST_F(Ed25519Crafted, KeysThatDoNotDecodeAreRejectedLikeLibsodium) {
  // Canonical y for which (y^2 - 1) / (d y^2 + 1) is no square: y = 2, 7, 8.
  const Bytes32 s{};
  const Bytes64 sig = join(torsion_multiples()[3], s);
  for (int y0 : {2, 7, 8, 11}) {
    for (std::uint8_t sign : {std::uint8_t{0}, std::uint8_t{0x80}}) {
      Bytes32 pk{};
      pk[0] = static_cast<std::uint8_t>(y0);
      pk[31] = sign;
      ed::Extended point;
      EXPECT_FALSE(ed::decode(point, pk));
      EXPECT_FALSE(verdict(sig, {}, pk, "y = " + std::to_string(y0)));
    }
  }
}

}  // namespace
}  // namespace hadynet::crypto::test
