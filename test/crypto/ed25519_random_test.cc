// Random key pairs (crypto_sign_seed_keypair, seeds from a fixed-seed
// PRNG: reproducible) and random messages of 0..300 bytes signed by
// crypto_sign_detached. For each: the valid signature, and the signature
// with one random bit flipped, the message with one random bit flipped (a
// random 1-byte message instead of the empty one), the public key with one
// random bit flipped, and a signature by another key. Tolerance: exact
// agreement with crypto_sign_verify_detached in every case; every valid
// signature is accepted.
//
// 4 shards x 500 keys = 2000 key pairs, 10 000 verdicts of each verifier;
// sharded so ctest runs them in parallel. About 0.6 s a shard in the
// release build, 6-10 s in the Debug ASan+UBSan build.
#include <sodium.h>

#include <cstdio>

#include "firmware/crypto/ed25519_verify.h"
#include "test/crypto/crypto_test_support.h"

namespace hadynet::crypto::test {
namespace {

constexpr int kShards = 4;
constexpr int kKeysPerShard = 500;

struct KeyPair {
  Bytes32 pk{};
  std::array<std::uint8_t, crypto_sign_SECRETKEYBYTES> sk{};
};

KeyPair make_key(Rng& rng) {
  const Bytes32 seed = rng.array<32>();
  KeyPair k;
  EXPECT_EQ(crypto_sign_seed_keypair(k.pk.data(), k.sk.data(), seed.data()), 0);
  return k;
}

Bytes64 sign(const KeyPair& k, const Bytes& message) {
  Bytes64 sig{};
  EXPECT_EQ(crypto_sign_detached(sig.data(), nullptr, message.data(), message.size(), k.sk.data()), 0);
  return sig;
}

void flip_bit(std::span<std::uint8_t> bytes, std::size_t bit) {
  bytes[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
}

class Ed25519Random : public ::testing::TestWithParam<int> {
 protected:
  static void SetUpTestSuite() { init_sodium(); }
};

TEST_P(Ed25519Random, VerdictsEqualLibsodiumOnValidAndAlteredSignatures) {
  Rng rng(0xed25'5190'0000u + static_cast<std::uint64_t>(GetParam()));
  enum Case { kValid, kSignatureBit, kMessageBit, kKeyBit, kOtherKey, kCases };
  const char* names[kCases] = {"valid", "signature bit", "message bit", "public key bit", "other key"};
  int accepted[kCases] = {};
  int disagreements[kCases] = {};

  KeyPair other = make_key(rng);
  for (int n = 0; n < kKeysPerShard; ++n) {
    const KeyPair key = make_key(rng);
    const Bytes message = rng.bytes(rng.below(301));
    const Bytes64 sig = sign(key, message);

    const auto check = [&](Case c, const Bytes64& s, const Bytes& m, const Bytes32& pk) {
      const bool ours = ed25519_verify(s, m, pk);
      const bool theirs = sodium_verify(s, m, pk);
      if (ours != theirs) {
        ++disagreements[c];
        ADD_FAILURE() << names[c] << ": ours " << ours << ", libsodium " << theirs << "\n  sig " << to_hex(s)
                      << "\n  pk " << to_hex(pk) << "\n  message " << to_hex(m);
      }
      accepted[c] += ours ? 1 : 0;
    };

    check(kValid, sig, message, key.pk);

    Bytes64 bad_sig = sig;
    flip_bit(bad_sig, rng.below(512));
    check(kSignatureBit, bad_sig, message, key.pk);

    Bytes bad_message = message;
    if (bad_message.empty()) {
      bad_message.push_back(rng.byte());
    } else {
      flip_bit(bad_message, rng.below(8 * bad_message.size()));
    }
    check(kMessageBit, sig, bad_message, key.pk);

    Bytes32 bad_pk = key.pk;
    flip_bit(bad_pk, rng.below(256));
    check(kKeyBit, sig, message, bad_pk);

    check(kOtherKey, sign(other, message), message, key.pk);
    other = key;
  }

  for (int c = 0; c < kCases; ++c) {
    EXPECT_EQ(disagreements[c], 0) << names[c];
    std::printf("shard %d, %s: %d of %d accepted by both\n", GetParam(), names[c], accepted[c], kKeysPerShard);
  }
  EXPECT_EQ(accepted[kValid], kKeysPerShard);  // every valid signature
}

INSTANTIATE_TEST_SUITE_P(Shards, Ed25519Random, ::testing::Range(0, kShards));

}  // namespace
}  // namespace hadynet::crypto::test
