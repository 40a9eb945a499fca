// SHA-256 and SHA-512 against libsodium's crypto_hash_sha256/512 (exact
// digests): every length 0..300 and random lengths up to 5000, fed whole, in
// random chunks and split at the block boundaries; typed-in FIPS 180
// examples; reuse after finish().
#include <sodium.h>

#include <algorithm>
#include <string_view>

#include "firmware/crypto/sha256.h"
#include "firmware/crypto/sha512.h"
#include "test/crypto/crypto_test_support.h"

namespace hadynet::crypto::test {
namespace {

struct Sha256Traits {
  using Hasher = Sha256;
  static constexpr std::size_t kBlock = 64;
  static constexpr std::size_t kDigest = kSha256Bytes;
  static_assert(kDigest == crypto_hash_sha256_BYTES, "the firmware's digest length is libsodium's");
  static Bytes oracle(std::span<const std::uint8_t> m) {
    Bytes d(crypto_hash_sha256_BYTES);
    crypto_hash_sha256(d.data(), m.data(), m.size());
    return d;
  }
  static Bytes one_shot(std::span<const std::uint8_t> m) {
    const auto d = sha256(m);
    return Bytes(d.begin(), d.end());
  }
};

struct Sha512Traits {
  using Hasher = Sha512;
  static constexpr std::size_t kBlock = 128;
  static constexpr std::size_t kDigest = kSha512Bytes;
  static_assert(kDigest == crypto_hash_sha512_BYTES, "the firmware's digest length is libsodium's");
  static Bytes oracle(std::span<const std::uint8_t> m) {
    Bytes d(crypto_hash_sha512_BYTES);
    crypto_hash_sha512(d.data(), m.data(), m.size());
    return d;
  }
  static Bytes one_shot(std::span<const std::uint8_t> m) {
    const auto d = sha512(m);
    return Bytes(d.begin(), d.end());
  }
};

template <typename H>
Bytes finish(H& h) {
  const auto d = h.finish();
  return Bytes(d.begin(), d.end());
}

// The message fed in chunks of random sizes 0..max_chunk (empty updates too).
template <typename T>
Bytes hash_in_random_chunks(std::span<const std::uint8_t> m, Rng& rng, std::size_t max_chunk) {
  typename T::Hasher h;
  std::size_t at = 0;
  while (at < m.size()) {
    const std::size_t n = std::min(rng.below(max_chunk + 1), m.size() - at);
    h.update(m.subspan(at, n));
    at += n;
  }
  return finish(h);
}

// The message fed as [0, split) and [split, end).
template <typename T>
Bytes hash_split(std::span<const std::uint8_t> m, std::size_t split) {
  typename T::Hasher h;
  h.update(m.first(split));
  h.update(m.subspan(split));
  return finish(h);
}

template <typename T>
class ShaTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { init_sodium(); }
};
using ShaTypes = ::testing::Types<Sha256Traits, Sha512Traits>;
TYPED_TEST_SUITE(ShaTest, ShaTypes);

TYPED_TEST(ShaTest, EveryLengthTo300WholeChunkedAndSplitMatchesLibsodium) {
  using T = TypeParam;
  Rng rng(0x5a17'0001 + T::kBlock);
  const Bytes data = rng.bytes(300);
  const std::size_t b = T::kBlock;
  // Block boundaries: where the padding's length field no longer fits
  // (b - 9, b - 8), the block end (b - 1, b, b + 1), and twice over.
  const std::size_t splits[] = {0, 1, b - 9, b - 8, b - 1, b, b + 1, 2 * b - 9, 2 * b - 8, 2 * b - 1, 2 * b};
  for (std::size_t len = 0; len <= 300; ++len) {
    const std::span<const std::uint8_t> m(data.data(), len);
    const Bytes expected = T::oracle(m);
    ASSERT_EQ(T::one_shot(m), expected) << "length " << len;
    ASSERT_EQ(hash_in_random_chunks<T>(m, rng, 2 * b + 3), expected) << "length " << len;
    ASSERT_EQ(hash_in_random_chunks<T>(m, rng, 3), expected) << "length " << len;
    for (std::size_t split : splits) {
      if (split <= len) {
        ASSERT_EQ(hash_split<T>(m, split), expected) << "length " << len << " split " << split;
      }
    }
  }
}

TYPED_TEST(ShaTest, RandomLengthsTo5000MatchLibsodium) {
  using T = TypeParam;
  Rng rng(0x5a17'0002 + T::kBlock);
  const Bytes data = rng.bytes(5000);
  for (int n = 0; n < 150; ++n) {
    const std::size_t len = rng.below(5001);
    const std::span<const std::uint8_t> m(data.data(), len);
    const Bytes expected = T::oracle(m);
    ASSERT_EQ(T::one_shot(m), expected) << "length " << len;
    ASSERT_EQ(hash_in_random_chunks<T>(m, rng, 700), expected) << "length " << len;
    ASSERT_EQ(hash_split<T>(m, rng.below(len + 1)), expected) << "length " << len;
  }
}

TYPED_TEST(ShaTest, FinishResetsTheObjectForReuse) {
  using T = TypeParam;
  Rng rng(0x5a17'0003);
  typename T::Hasher h;
  for (std::size_t len : {0u, 3u, 200u, 129u, 64u}) {
    const Bytes m = rng.bytes(len);
    h.update(m);
    EXPECT_EQ(finish(h), T::oracle(m)) << "length " << len;
  }
  EXPECT_EQ(finish(h), T::oracle({}));  // finish() straight after finish(): the empty message
}

TYPED_TEST(ShaTest, OneMillionAInChunksMatchesLibsodium) {
  using T = TypeParam;
  const Bytes a(1'000'000, 'a');
  typename T::Hasher h;
  Rng rng(0x5a17'0004);
  std::size_t at = 0;
  while (at < a.size()) {
    const std::size_t n = std::min(rng.below(10'000), a.size() - at);
    h.update(std::span<const std::uint8_t>(a).subspan(at, n));
    at += n;
  }
  EXPECT_EQ(finish(h), T::oracle(a));
}

Bytes ascii(std::string_view s) { return Bytes(s.begin(), s.end()); }

// FIPS 180 examples (FIPS 180-2 Appendix B/C; NIST's SHA examples), typed in.
TEST(Sha256, Fips180Vectors) {
  const auto digest = [](std::string_view s) {
    const auto d = sha256(ascii(s));
    return to_hex(d);
  };
  EXPECT_EQ(digest(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(digest("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(digest("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha512, Fips180Vectors) {
  const auto digest = [](std::string_view s) {
    const auto d = sha512(ascii(s));
    return to_hex(d);
  };
  EXPECT_EQ(digest(""),
            "cf83e1357eefb8bdf1542850d66d8007d620e4050b5715dc83f4a921d36ce9ce"
            "47d0d13c5d85f2b0ff8318d2877eec2f63b931bd47417a81a538327af927da3e");
  EXPECT_EQ(digest("abc"),
            "ddaf35a193617abacc417349ae20413112e6fa4e89a97ea20a9eeee64b55d39a"
            "2192992a274fc1a836ba3c23a3feebbd454d4423643ce80e2a9ac94fa54ca49f");
  EXPECT_EQ(digest("abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmno"
                   "ijklmnopjklmnopqklmnopqrlmnopqrsmnopqrstnopqrstu"),
            "8e959b75dae313da8cf4f72814fc143f8f7779c6eb9f7fa17299aeadb6889018"
            "501d289e4900f7e4331b99dec4b5433ac7d329eeb6dd26545e96e55b874be909");
}

}  // namespace
}  // namespace hadynet::crypto::test
