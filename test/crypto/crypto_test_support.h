// Shared helpers of the crypto tests: hex, a reproducible byte source, and
// libsodium (the oracle) behind small wrappers.
#ifndef HADYNET_TEST_CRYPTO_CRYPTO_TEST_SUPPORT_H_
#define HADYNET_TEST_CRYPTO_CRYPTO_TEST_SUPPORT_H_

#include <gtest/gtest.h>
#include <sodium.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hadynet::crypto::test {

using Bytes = std::vector<std::uint8_t>;
using Bytes32 = std::array<std::uint8_t, 32>;
using Bytes64 = std::array<std::uint8_t, 64>;

inline Bytes from_hex(std::string_view hex) {
  auto nibble = [](char c) -> std::uint8_t {
    if (c >= '0' && c <= '9') return static_cast<std::uint8_t>(c - '0');
    if (c >= 'a' && c <= 'f') return static_cast<std::uint8_t>(c - 'a' + 10);
    if (c >= 'A' && c <= 'F') return static_cast<std::uint8_t>(c - 'A' + 10);
    ADD_FAILURE() << "not a hex digit: " << c;
    return 0;
  };
  EXPECT_EQ(hex.size() % 2, 0u);
  Bytes out;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2) {
    out.push_back(static_cast<std::uint8_t>((nibble(hex[i]) << 4) | nibble(hex[i + 1])));
  }
  return out;
}

template <std::size_t N>
std::array<std::uint8_t, N> array_from_hex(std::string_view hex) {
  const Bytes b = from_hex(hex);
  std::array<std::uint8_t, N> out{};
  EXPECT_EQ(b.size(), N) << hex;
  for (std::size_t i = 0; i < N && i < b.size(); ++i) out[i] = b[i];
  return out;
}

inline std::string to_hex(std::span<const std::uint8_t> bytes) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string s;
  for (std::uint8_t b : bytes) {
    s.push_back(kDigits[b >> 4]);
    s.push_back(kDigits[b & 15]);
  }
  return s;
}

// A reproducible byte source: std::mt19937_64's output sequence is fixed by
// the C++ standard, and only its raw outputs are used (no distributions,
// whose results differ between standard libraries).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  std::uint64_t next() { return engine_(); }
  // Uniform enough in [0, n) for tests (n small against 2^64).
  std::size_t below(std::size_t n) { return static_cast<std::size_t>(next() % n); }
  std::uint8_t byte() { return static_cast<std::uint8_t>(next()); }
  Bytes bytes(std::size_t n) {
    Bytes b(n);
    for (auto& x : b) x = byte();
    return b;
  }
  template <std::size_t N>
  std::array<std::uint8_t, N> array() {
    std::array<std::uint8_t, N> a{};
    for (auto& x : a) x = byte();
    return a;
  }

 private:
  std::mt19937_64 engine_;
};

inline void init_sodium() { ASSERT_GE(sodium_init(), 0); }

// libsodium's verdict: crypto_sign_verify_detached() == 0.
inline bool sodium_verify(std::span<const std::uint8_t, 64> sig, std::span<const std::uint8_t> message,
                          std::span<const std::uint8_t, 32> public_key) {
  return crypto_sign_verify_detached(sig.data(), message.data(), message.size(), public_key.data()) == 0;
}

// A signature laid out as R || S.
inline Bytes64 join(const Bytes32& r, const Bytes32& s) {
  Bytes64 sig{};
  for (std::size_t i = 0; i < 32; ++i) {
    sig[i] = r[i];
    sig[32 + i] = s[i];
  }
  return sig;
}

// libsodium's scalar arithmetic mod L and base-point multiplication.
inline Bytes32 sodium_reduce(std::span<const std::uint8_t, 64> wide) {
  Bytes32 r{};
  crypto_core_ed25519_scalar_reduce(r.data(), wide.data());
  return r;
}
inline Bytes32 sodium_scalar_add(const Bytes32& a, const Bytes32& b) {
  Bytes32 r{};
  crypto_core_ed25519_scalar_add(r.data(), a.data(), b.data());
  return r;
}
inline Bytes32 sodium_scalar_mul(const Bytes32& a, const Bytes32& b) {
  Bytes32 r{};
  crypto_core_ed25519_scalar_mul(r.data(), a.data(), b.data());
  return r;
}
// [s]B for 0 < s < L (libsodium refuses 0).
inline Bytes32 sodium_base_mul(const Bytes32& s) {
  Bytes32 q{};
  EXPECT_EQ(crypto_scalarmult_ed25519_base_noclamp(q.data(), s.data()), 0);
  return q;
}
// k = SHA-512(R || A || M) mod L, by libsodium.
inline Bytes32 sodium_challenge(const Bytes32& r, std::span<const std::uint8_t, 32> a,
                                std::span<const std::uint8_t> message) {
  crypto_hash_sha512_state st;
  crypto_hash_sha512_init(&st);
  crypto_hash_sha512_update(&st, r.data(), r.size());
  crypto_hash_sha512_update(&st, a.data(), a.size());
  crypto_hash_sha512_update(&st, message.data(), message.size());
  Bytes64 h{};
  crypto_hash_sha512_final(&st, h.data());
  return sodium_reduce(h);
}

// L, little-endian.
inline const Bytes32& order_l() {
  static const Bytes32 l = array_from_hex<32>("edd3f55c1a631258d69cf7a2def9de1400000000000000000000000000000010");
  return l;
}

// a + b as 256-bit little-endian integers (mod 2^256).
inline Bytes32 add_256(const Bytes32& a, const Bytes32& b) {
  Bytes32 r{};
  unsigned carry = 0;
  for (std::size_t i = 0; i < 32; ++i) {
    const unsigned t = unsigned{a[i]} + unsigned{b[i]} + carry;
    r[i] = static_cast<std::uint8_t>(t);
    carry = t >> 8;
  }
  return r;
}

// The eight points of small order, [j]T for j = 0..7, T a point of order 8
// with even x: [0]T = identity (order 1), [4]T = (0, -1) (order 2), [2]T and
// [6]T (y = 0, order 4), the odd multiples of order 8. Typed in (worked out
// from the curve equation); curve_test.cc checks them against libsodium's
// point addition and checks their orders.
inline const std::array<Bytes32, 8>& torsion_multiples() {
  static const std::array<Bytes32, 8> t = [] {
    std::array<Bytes32, 8> m{};
    const char* hex[8] = {
        "0100000000000000000000000000000000000000000000000000000000000000",
        "26e8958fc2b227b045c3f489f2ef98f0d5dfac05d3c63339b13802886d53fc05",
        "0000000000000000000000000000000000000000000000000000000000000000",
        "c7176a703d4dd84fba3c0b760d10670f2a2053fa2c39ccc64ec7fd7792ac037a",
        "ecffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff7f",
        "c7176a703d4dd84fba3c0b760d10670f2a2053fa2c39ccc64ec7fd7792ac03fa",
        "0000000000000000000000000000000000000000000000000000000000000080",
        "26e8958fc2b227b045c3f489f2ef98f0d5dfac05d3c63339b13802886d53fc85",
    };
    for (std::size_t j = 0; j < 8; ++j) m[j] = array_from_hex<32>(hex[j]);
    return m;
  }();
  return t;
}

}  // namespace hadynet::crypto::test

#endif  // HADYNET_TEST_CRYPTO_CRYPTO_TEST_SUPPORT_H_
