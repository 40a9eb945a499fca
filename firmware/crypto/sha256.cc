// SHA-256 from FIPS 180-4: §4.1.2 functions, §4.2.2 constants, §5.1.1
// padding, §5.3.3 initial value, §6.2.2 computation.
#include "firmware/crypto/sha256.h"

#include <algorithm>

namespace hadynet::crypto {
namespace {

// §5.3.3: the first 32 bits of the fractional parts of the square roots of
// the first 8 primes.
constexpr std::array<std::uint32_t, 8> kInitial = {
    0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19,
};

// §4.2.2: the first 32 bits of the fractional parts of the cube roots of the
// first 64 primes.
constexpr std::array<std::uint32_t, 64> kRound = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2,
};

constexpr std::uint32_t rotr(std::uint32_t x, int n) noexcept { return (x >> n) | (x << (32 - n)); }
constexpr std::uint32_t ch(std::uint32_t x, std::uint32_t y, std::uint32_t z) noexcept { return (x & y) ^ (~x & z); }
constexpr std::uint32_t maj(std::uint32_t x, std::uint32_t y, std::uint32_t z) noexcept {
  return (x & y) ^ (x & z) ^ (y & z);
}
constexpr std::uint32_t big_sigma0(std::uint32_t x) noexcept { return rotr(x, 2) ^ rotr(x, 13) ^ rotr(x, 22); }
constexpr std::uint32_t big_sigma1(std::uint32_t x) noexcept { return rotr(x, 6) ^ rotr(x, 11) ^ rotr(x, 25); }
constexpr std::uint32_t small_sigma0(std::uint32_t x) noexcept { return rotr(x, 7) ^ rotr(x, 18) ^ (x >> 3); }
constexpr std::uint32_t small_sigma1(std::uint32_t x) noexcept { return rotr(x, 17) ^ rotr(x, 19) ^ (x >> 10); }

std::uint32_t load_be32(const std::uint8_t* p) noexcept {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | std::uint32_t{p[3]};
}

void store_be32(std::uint8_t* p, std::uint32_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}

// §6.2.2 on one 64-byte block. The message schedule W_t is kept as a ring of
// its last 16 words (W_t depends only on W_{t-2}, W_{t-7}, W_{t-15}, W_{t-16}).
void compress(std::array<std::uint32_t, 8>& h, const std::uint8_t* block) noexcept {
  std::uint32_t w[16];
  std::uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4], f = h[5], g = h[6], k = h[7];
  for (int t = 0; t < 64; ++t) {
    std::uint32_t wt;
    if (t < 16) {
      wt = load_be32(block + 4 * t);
    } else {
      wt = small_sigma1(w[(t - 2) & 15]) + w[(t - 7) & 15] + small_sigma0(w[(t - 15) & 15]) + w[t & 15];
    }
    w[t & 15] = wt;
    const std::uint32_t t1 = k + big_sigma1(e) + ch(e, f, g) + kRound[static_cast<std::size_t>(t)] + wt;
    const std::uint32_t t2 = big_sigma0(a) + maj(a, b, c);
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

Sha256::Sha256() noexcept { reset(); }

void Sha256::reset() noexcept {
  state_ = kInitial;
  block_used_ = 0;
  message_bytes_ = 0;
}

void Sha256::update(std::span<const std::uint8_t> data) noexcept {
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

std::array<std::uint8_t, kSha256Bytes> Sha256::finish() noexcept {
  // §5.1.1: a 1 bit, zeros up to 56 mod 64 bytes, the length in bits as a
  // 64-bit big-endian integer.
  const std::uint64_t bit_length = message_bytes_ * 8;
  block_[block_used_++] = 0x80;
  if (block_used_ > kBlockBytes - 8) {
    std::fill(block_.begin() + static_cast<std::ptrdiff_t>(block_used_), block_.end(), std::uint8_t{0});
    compress(state_, block_.data());
    block_used_ = 0;
  }
  std::fill(block_.begin() + static_cast<std::ptrdiff_t>(block_used_), block_.end() - 8, std::uint8_t{0});
  store_be32(block_.data() + kBlockBytes - 8, static_cast<std::uint32_t>(bit_length >> 32));
  store_be32(block_.data() + kBlockBytes - 4, static_cast<std::uint32_t>(bit_length));
  compress(state_, block_.data());

  std::array<std::uint8_t, kSha256Bytes> digest{};
  for (std::size_t i = 0; i < 8; ++i) store_be32(digest.data() + 4 * i, state_[i]);
  reset();
  return digest;
}

std::array<std::uint8_t, kSha256Bytes> sha256(std::span<const std::uint8_t> data) noexcept {
  Sha256 h;
  h.update(data);
  return h.finish();
}

}  // namespace hadynet::crypto
