// SHA-512 from FIPS 180-4: §4.1.3 functions, §4.2.3 constants, §5.1.2
// padding, §5.3.5 initial value, §6.4.2 computation.
#include "firmware/crypto/sha512.h"

#include <algorithm>

namespace hadynet::crypto {
namespace {

// §5.3.5: the first 64 bits of the fractional parts of the square roots of
// the first 8 primes.
constexpr std::array<std::uint64_t, 8> kInitial = {
    0x6a09e667f3bcc908, 0xbb67ae8584caa73b, 0x3c6ef372fe94f82b, 0xa54ff53a5f1d36f1,
    0x510e527fade682d1, 0x9b05688c2b3e6c1f, 0x1f83d9abfb41bd6b, 0x5be0cd19137e2179,
};

// §4.2.3: the first 64 bits of the fractional parts of the cube roots of the
// first 80 primes.
constexpr std::array<std::uint64_t, 80> kRound = {
    0x428a2f98d728ae22, 0x7137449123ef65cd, 0xb5c0fbcfec4d3b2f, 0xe9b5dba58189dbbc, 0x3956c25bf348b538,
    0x59f111f1b605d019, 0x923f82a4af194f9b, 0xab1c5ed5da6d8118, 0xd807aa98a3030242, 0x12835b0145706fbe,
    0x243185be4ee4b28c, 0x550c7dc3d5ffb4e2, 0x72be5d74f27b896f, 0x80deb1fe3b1696b1, 0x9bdc06a725c71235,
    0xc19bf174cf692694, 0xe49b69c19ef14ad2, 0xefbe4786384f25e3, 0x0fc19dc68b8cd5b5, 0x240ca1cc77ac9c65,
    0x2de92c6f592b0275, 0x4a7484aa6ea6e483, 0x5cb0a9dcbd41fbd4, 0x76f988da831153b5, 0x983e5152ee66dfab,
    0xa831c66d2db43210, 0xb00327c898fb213f, 0xbf597fc7beef0ee4, 0xc6e00bf33da88fc2, 0xd5a79147930aa725,
    0x06ca6351e003826f, 0x142929670a0e6e70, 0x27b70a8546d22ffc, 0x2e1b21385c26c926, 0x4d2c6dfc5ac42aed,
    0x53380d139d95b3df, 0x650a73548baf63de, 0x766a0abb3c77b2a8, 0x81c2c92e47edaee6, 0x92722c851482353b,
    0xa2bfe8a14cf10364, 0xa81a664bbc423001, 0xc24b8b70d0f89791, 0xc76c51a30654be30, 0xd192e819d6ef5218,
    0xd69906245565a910, 0xf40e35855771202a, 0x106aa07032bbd1b8, 0x19a4c116b8d2d0c8, 0x1e376c085141ab53,
    0x2748774cdf8eeb99, 0x34b0bcb5e19b48a8, 0x391c0cb3c5c95a63, 0x4ed8aa4ae3418acb, 0x5b9cca4f7763e373,
    0x682e6ff3d6b2b8a3, 0x748f82ee5defb2fc, 0x78a5636f43172f60, 0x84c87814a1f0ab72, 0x8cc702081a6439ec,
    0x90befffa23631e28, 0xa4506cebde82bde9, 0xbef9a3f7b2c67915, 0xc67178f2e372532b, 0xca273eceea26619c,
    0xd186b8c721c0c207, 0xeada7dd6cde0eb1e, 0xf57d4f7fee6ed178, 0x06f067aa72176fba, 0x0a637dc5a2c898a6,
    0x113f9804bef90dae, 0x1b710b35131c471b, 0x28db77f523047d84, 0x32caab7b40c72493, 0x3c9ebe0a15c9bebc,
    0x431d67c49c100d4c, 0x4cc5d4becb3e42b6, 0x597f299cfc657e2a, 0x5fcb6fab3ad6faec, 0x6c44198c4a475817,
};

constexpr std::uint64_t rotr(std::uint64_t x, int n) noexcept { return (x >> n) | (x << (64 - n)); }
constexpr std::uint64_t ch(std::uint64_t x, std::uint64_t y, std::uint64_t z) noexcept { return (x & y) ^ (~x & z); }
constexpr std::uint64_t maj(std::uint64_t x, std::uint64_t y, std::uint64_t z) noexcept {
  return (x & y) ^ (x & z) ^ (y & z);
}
constexpr std::uint64_t big_sigma0(std::uint64_t x) noexcept { return rotr(x, 28) ^ rotr(x, 34) ^ rotr(x, 39); }
constexpr std::uint64_t big_sigma1(std::uint64_t x) noexcept { return rotr(x, 14) ^ rotr(x, 18) ^ rotr(x, 41); }
constexpr std::uint64_t small_sigma0(std::uint64_t x) noexcept { return rotr(x, 1) ^ rotr(x, 8) ^ (x >> 7); }
constexpr std::uint64_t small_sigma1(std::uint64_t x) noexcept { return rotr(x, 19) ^ rotr(x, 61) ^ (x >> 6); }

std::uint64_t load_be64(const std::uint8_t* p) noexcept {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return v;
}

void store_be64(std::uint8_t* p, std::uint64_t v) noexcept {
  for (int i = 7; i >= 0; --i) {
    p[i] = static_cast<std::uint8_t>(v);
    v >>= 8;
  }
}

// §6.4.2 on one 128-byte block, the message schedule kept as a ring of its
// last 16 words (as in sha256.cc).
void compress(std::array<std::uint64_t, 8>& h, const std::uint8_t* block) noexcept {
  std::uint64_t w[16];
  std::uint64_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4], f = h[5], g = h[6], k = h[7];
  for (int t = 0; t < 80; ++t) {
    std::uint64_t wt;
    if (t < 16) {
      wt = load_be64(block + 8 * t);
    } else {
      wt = small_sigma1(w[(t - 2) & 15]) + w[(t - 7) & 15] + small_sigma0(w[(t - 15) & 15]) + w[t & 15];
    }
    w[t & 15] = wt;
    const std::uint64_t t1 = k + big_sigma1(e) + ch(e, f, g) + kRound[static_cast<std::size_t>(t)] + wt;
    const std::uint64_t t2 = big_sigma0(a) + maj(a, b, c);
    k = g;
    g = f;
    f = e;
    e = d + t1;
    d = c;
    c = b;
    b = a;
    a = t1 + t2;
  }
  h[0] += a;
  h[1] += b;
  h[2] += c;
  h[3] += d;
  h[4] += e;
  h[5] += f;
  h[6] += g;
  h[7] += k;
}

}  // namespace

Sha512::Sha512() noexcept { reset(); }

void Sha512::reset() noexcept {
  state_ = kInitial;
  block_used_ = 0;
  message_bytes_ = 0;
}

void Sha512::update(std::span<const std::uint8_t> data) noexcept {
  message_bytes_ += data.size();
  if (block_used_ != 0) {
    const std::size_t n = std::min(data.size(), kBlockBytes - block_used_);
    std::copy_n(data.begin(), n, block_.begin() + static_cast<std::ptrdiff_t>(block_used_));
    block_used_ += n;
    data = data.subspan(n);
    if (block_used_ < kBlockBytes) return;
    compress(state_, block_.data());
    block_used_ = 0;
  }
  while (data.size() >= kBlockBytes) {
    compress(state_, data.data());
    data = data.subspan(kBlockBytes);
  }
  std::copy(data.begin(), data.end(), block_.begin());
  block_used_ = data.size();
}

std::array<std::uint8_t, kSha512Bytes> Sha512::finish() noexcept {
  // §5.1.2: a 1 bit, zeros up to 112 mod 128 bytes, the length in bits as a
  // 128-bit big-endian integer (its high word is the byte count's top 3 bits).
  const std::uint64_t bit_length_high = message_bytes_ >> 61;
  const std::uint64_t bit_length_low = message_bytes_ << 3;
  block_[block_used_++] = 0x80;
  if (block_used_ > kBlockBytes - 16) {
    std::fill(block_.begin() + static_cast<std::ptrdiff_t>(block_used_), block_.end(), std::uint8_t{0});
    compress(state_, block_.data());
    block_used_ = 0;
  }
  std::fill(block_.begin() + static_cast<std::ptrdiff_t>(block_used_), block_.end() - 16, std::uint8_t{0});
  store_be64(block_.data() + kBlockBytes - 16, bit_length_high);
  store_be64(block_.data() + kBlockBytes - 8, bit_length_low);
  compress(state_, block_.data());

  std::array<std::uint8_t, kSha512Bytes> digest{};
  for (std::size_t i = 0; i < 8; ++i) store_be64(digest.data() + 8 * i, state_[i]);
  reset();
  return digest;
}

std::array<std::uint8_t, kSha512Bytes> sha512(std::span<const std::uint8_t> data) noexcept {
  Sha512 h;
  h.update(data);
  return h.finish();
}

}  // namespace hadynet::crypto
