// COBS and CRC-32 against published known answers, and COBS round trips over
// the edge cases of the block structure (empty, zeros, 254/255-byte runs,
// the largest frame). Everything here is exact: encodings are byte strings.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "firmware/link/cobs.h"
#include "firmware/link/crc32.h"
#include "firmware/link/frame.h"

namespace hadynet::link {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::span<const std::uint8_t> as_bytes(std::string_view s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

Bytes encode(const Bytes& in) {
  Bytes out(cobs_max_encoded_size(in.size()));
  const std::size_t n = cobs_encode(in, out);
  EXPECT_GT(n, 0u);
  out.resize(n);
  return out;
}

Bytes run(std::uint8_t first, std::size_t n) {  // first, first + 1, ... (wrapping, skipping 0)
  Bytes b;
  std::uint8_t v = first;
  for (std::size_t i = 0; i < n; ++i) {
    if (v == 0) v = 1;
    b.push_back(v++);
  }
  return b;
}

Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// Check values of CRC-32/ISO-HDLC (the zlib / IEEE 802.3 CRC), from the
// CRC catalogue and zlib's crc32().
TEST(LinkCrc32, KnownAnswers) {
  static_assert(crc32(std::span<const std::uint8_t>{}) == 0);
  EXPECT_EQ(crc32(as_bytes("123456789")), 0xCBF43926u);
  EXPECT_EQ(crc32(as_bytes("a")), 0xE8B7BE43u);
  EXPECT_EQ(crc32(as_bytes("The quick brown fox jumps over the lazy dog")), 0x414FA339u);
  const Bytes zeros(32, 0);
  EXPECT_EQ(crc32(zeros), 0x190A55ADu);
}

TEST(LinkCrc32, IncrementalEqualsOneShot) {
  const std::string_view s = "The quick brown fox jumps over the lazy dog";
  for (std::size_t cut = 0; cut <= s.size(); ++cut) {
    std::uint32_t state = crc32_begin();
    state = crc32_update(state, as_bytes(s.substr(0, cut)));
    state = crc32_update(state, as_bytes(s.substr(cut)));
    EXPECT_EQ(crc32_end(state), 0x414FA339u) << "cut at " << cut;
  }
}

// The examples of the COBS paper (Cheshire & Baker) and of its common
// descriptions, including the 254/255-byte block boundaries.
TEST(LinkCobs, KnownEncodings) {
  struct Case {
    Bytes in, out;
  };
  const std::vector<Case> cases = {
      {{}, {0x01}},
      {{0x00}, {0x01, 0x01}},
      {{0x00, 0x00}, {0x01, 0x01, 0x01}},
      {{0x00, 0x11, 0x00}, {0x01, 0x02, 0x11, 0x01}},
      {{0x11, 0x22, 0x00, 0x33}, {0x03, 0x11, 0x22, 0x02, 0x33}},
      {{0x11, 0x22, 0x33, 0x44}, {0x05, 0x11, 0x22, 0x33, 0x44}},
      {{0x11, 0x00, 0x00, 0x00}, {0x02, 0x11, 0x01, 0x01, 0x01}},
      {run(0x01, 254), concat({{0xFF}, run(0x01, 254)})},                                        // 01..FE
      {concat({{0x00}, run(0x01, 254)}), concat({{0x01, 0xFF}, run(0x01, 254)})},                // 00 01..FE
      {run(0x01, 255), concat({{0xFF}, run(0x01, 254), {0x02, 0xFF}})},                          // 01..FF
      {concat({run(0x02, 254), {0x00}}), concat({{0xFF}, run(0x02, 254), {0x01, 0x01}})},        // 02..FF 00
      {concat({run(0x03, 253), {0x00, 0x01}}), concat({{0xFE}, run(0x03, 253), {0x02, 0x01}})},  // 03..FF 00 01
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    EXPECT_EQ(encode(cases[i].in), cases[i].out) << "case " << i;
    Bytes back(cases[i].in.size() + 1);
    const CobsDecodeResult r = cobs_decode(cases[i].out, back);
    ASSERT_EQ(r.status, CobsStatus::kOk) << "case " << i;
    back.resize(r.size);
    EXPECT_EQ(back, cases[i].in) << "case " << i;
  }
}

// Deterministic pseudo-random bytes (LCG), a given fraction of them zero.
Bytes pseudo_random(std::size_t n, std::uint32_t seed, int zero_every) {
  Bytes b(n);
  std::uint32_t s = seed;
  for (auto& v : b) {
    s = s * 1664525u + 1013904223u;
    v = static_cast<std::uint8_t>(s >> 24);
    if (zero_every > 0 && (s >> 8) % static_cast<std::uint32_t>(zero_every) == 0) v = 0;
  }
  return b;
}

void expect_round_trip(const Bytes& in, const std::string& what) {
  const Bytes enc = encode(in);
  EXPECT_LE(enc.size(), cobs_max_encoded_size(in.size())) << what;
  for (std::uint8_t b : enc) ASSERT_NE(b, 0) << what << ": encoding contains a zero";
  Bytes out(in.size());  // exactly the decoded size: the decoder must not need more
  const CobsDecodeResult r = cobs_decode(enc, out);
  ASSERT_EQ(r.status, CobsStatus::kOk) << what;
  ASSERT_EQ(r.size, in.size()) << what;
  EXPECT_EQ(out, in) << what;
}

TEST(LinkCobs, RoundTripEdgeCases) {
  expect_round_trip({}, "empty");
  for (std::size_t n :
       std::initializer_list<std::size_t>{1, 2, 253, 254, 255, 256, 508, 509, kMaxFrame, kMaxEncodedFrame}) {
    expect_round_trip(Bytes(n, 0), "all zeros, " + std::to_string(n));
    expect_round_trip(Bytes(n, 0xAB), "no zeros, " + std::to_string(n));
    expect_round_trip(concat({Bytes(n, 0x55), {0x00}}), "run then zero, " + std::to_string(n));
    expect_round_trip(concat({{0x00}, Bytes(n, 0x55)}), "zero then run, " + std::to_string(n));
  }
  // The largest frame a sender may send, without zeros: its encoding is the
  // worst case and must fit the receiver's hard limit.
  const Bytes largest(kMaxFrame, 0x7E);
  EXPECT_EQ(encode(largest).size(), cobs_max_encoded_size(kMaxFrame));
  EXPECT_LE(encode(largest).size(), kMaxEncodedFrame);
  for (std::size_t n = 0; n <= 700; n += 7) {
    for (int zero_every : {0, 2, 50, 300}) {
      expect_round_trip(pseudo_random(n, static_cast<std::uint32_t>(n * 31 + 7), zero_every),
                        "pseudo-random n=" + std::to_string(n) + " zero_every=" + std::to_string(zero_every));
    }
  }
}

TEST(LinkCobs, EncodeChecksTheOutputSize) {
  for (const Bytes& in : {Bytes{}, Bytes{0x00}, run(0x01, 254), run(0x01, 255), pseudo_random(300, 5, 40)}) {
    const Bytes enc = encode(in);
    Bytes out(enc.size());
    EXPECT_EQ(cobs_encode(in, out), enc.size());
    Bytes small(enc.size() - 1);
    EXPECT_EQ(cobs_encode(in, small), 0u) << "input size " << in.size();
  }
}

TEST(LinkCobs, DecodeRejectsMalformedInput) {
  Bytes out(16);
  EXPECT_EQ(cobs_decode(Bytes{}, out).status, CobsStatus::kTruncated);            // no block at all
  EXPECT_EQ(cobs_decode(Bytes{0x03, 0x11}, out).status, CobsStatus::kTruncated);  // block cut short
  EXPECT_EQ(cobs_decode(Bytes{0x02, 0x11, 0x05}, out).status, CobsStatus::kTruncated);
  EXPECT_EQ(cobs_decode(Bytes{0x02, 0x00}, out).status, CobsStatus::kZeroInInput);
  Bytes tiny(2);
  EXPECT_EQ(cobs_decode(Bytes{0x04, 0x11, 0x22, 0x33}, tiny).status, CobsStatus::kOutputFull);
  EXPECT_EQ(cobs_decode(Bytes{0x03, 0x11, 0x22, 0x01}, tiny).status, CobsStatus::kOutputFull);  // the zero
}

}  // namespace
}  // namespace hadynet::link
