// The HID telemetry wire format (telemetry_report.h) and the host decoder
// (telemetry_decoder.h). Layout checks compare with bytes assembled here by
// hand from docs/usb.md's offsets (not with the encoder); floats travel as
// their bit patterns, so every comparison is exact (tolerance zero), -0.0
// and NaN payloads included.
//
// Version 3: the payload is the link's 0x88 period result (an
// app::PeriodRecord with its kRecord* flags) with the on-device
// adaptation's count and recognition. For the hand's model (kLoadcells 9,
// kY 27, kU 8) that is 23 + 4 (9 + 1 + 27 + 8) + 16 = 219 bytes, so a set has
// 4 reports (56, 56, 56, 51 payload bytes), as version 2 (203 bytes) had.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cstring>
#include <vector>

#include "firmware/app/period_record.h"
#include "firmware/link/messages.h"
#include "firmware/usb/telemetry_decoder.h"
#include "firmware/usb/telemetry_report.h"
#include "hadynet_model_q15.h"
#include "period_record_bits.h"

namespace hadynet::usb {
namespace {

using Q = model_q15::Model;
using Bytes = std::vector<std::uint8_t>;
using L = TelemetryLayout<Q>;
using Decoder = TelemetryDecoder<Q>;
using testing::expect_same_bits;
constexpr std::size_t kSet = L::kParts * kTelemetryReportSize;
constexpr int kLc = app::ChannelLayout<Q>::kLoadcells;

app::PeriodRecord<Q> sample_record(std::uint32_t sequence) {
  app::PeriodRecord<Q> r;
  r.sequence = sequence;
  r.period = 1000 + sequence;
  r.mode = firmware::Mode::kControl;
  r.flags = app::kRecordPredictionValid | app::kRecordDistanceValid | app::kRecordContact |
            app::kRecordCommandValid | app::kRecordStepped | app::kRecordStaleMuscleState | app::kRecordOverrun;
  r.muscle_state_age = 2;
  r.overruns = 0x0A0B0C0Du;
  r.missed_periods = 998;
  for (int k = 0; k < kLc; ++k) r.loadcells_N[k] = 0.25f * static_cast<float>(k) - 1.0f;
  r.d = 17.25f;
  for (int i = 0; i < Q::kY; ++i) r.prediction[i] = 0.5f * static_cast<float>(i) - 3.0f;
  for (int i = 0; i < Q::kU; ++i) r.command[i] = -1.0f / static_cast<float>(i + 1);
  r.command[0] = -0.0f;                                 // a sign bit only the bit pattern keeps
  r.prediction[5] = std::bit_cast<float>(0x7FC12345u);  // NaN payloads only the bit pattern keeps
  r.loadcells_N[8] = std::bit_cast<float>(0xFFC00001u);
  r.flags |= app::kRecordRecognition;
  r.adapt_updates = 0x11223344u;
  r.recognized_state = 3;
  r.recognized_distance = 0.375f;
  r.other_object_state = app::kRecordNoOtherObject;
  r.other_object_distance = 0.0f;
  return r;
}

std::array<std::uint8_t, kSet> encode(const app::PeriodRecord<Q>& r) {
  std::array<std::uint8_t, kSet> out{};
  encode_telemetry_reports<Q>(r, out);
  return out;
}

void put32(Bytes& b, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}
void putf(Bytes& b, float v) { put32(b, std::bit_cast<std::uint32_t>(v)); }

// The payload bytes of the reports of one set, concatenated.
Bytes payload_of(const std::array<std::uint8_t, kSet>& reports) {
  Bytes p;
  for (std::size_t part = 0; part < L::kParts; ++part) {
    const std::uint8_t* rep = reports.data() + 64 * part;
    p.insert(p.end(), rep + 8, rep + 8 + rep[3]);
  }
  return p;
}

TEST(UsbTelemetry, TheHandsModelNeedsFourReports) {
  // kLoadcells 9, kY 27, kU 8: 23 + 4 * (9 + 1 + 27 + 8) + 16 = 219
  // payload bytes, 56 per report.
  EXPECT_EQ(kLc, 9);
  EXPECT_EQ(Q::kY, 27);
  EXPECT_EQ(Q::kU, 8);
  EXPECT_EQ(L::kPayloadSize, 219u);
  EXPECT_EQ(L::kParts, 4u);
  EXPECT_EQ(kTelemetryFormatVersion, 3);
}

TEST(UsbTelemetry, ReportBytesFollowTheDocumentedLayout) {
  const app::PeriodRecord<Q> r = sample_record(0x01020304);
  // The payload assembled by hand, docs/usb.md = docs/protocol.md 0x88:
  // sequence u32, period u32, mode u8, flags u16, muscle_state_age u32,
  // overruns u32, missed_periods u32, loadcells[kLoadcells] f32, d f32,
  // prediction[kY] f32, command[kU] f32, adapt_updates u32,
  // recognized_state u16, recognized_distance f32, other_object_state u16,
  // other_object_distance f32, little-endian, no padding.
  Bytes payload;
  put32(payload, r.sequence);
  put32(payload, r.period);
  payload.push_back(2);  // control
  payload.push_back(static_cast<std::uint8_t>(r.flags));
  payload.push_back(static_cast<std::uint8_t>(r.flags >> 8));
  put32(payload, r.muscle_state_age);
  put32(payload, r.overruns);
  put32(payload, r.missed_periods);
  for (int k = 0; k < kLc; ++k) putf(payload, r.loadcells_N[k]);
  putf(payload, r.d);
  for (const float v : r.prediction) putf(payload, v);
  for (const float v : r.command) putf(payload, v);
  put32(payload, r.adapt_updates);
  payload.push_back(static_cast<std::uint8_t>(r.recognized_state));
  payload.push_back(static_cast<std::uint8_t>(r.recognized_state >> 8));
  putf(payload, r.recognized_distance);
  payload.push_back(static_cast<std::uint8_t>(r.other_object_state));
  payload.push_back(static_cast<std::uint8_t>(r.other_object_state >> 8));
  putf(payload, r.other_object_distance);
  ASSERT_EQ(payload.size(), 219u);
  // The documented offsets of the hand's model.
  EXPECT_EQ((Bytes{payload[8], payload[9], payload[10]}), (Bytes{0x02, 0x3F, 0x03})) << "mode 8, flags 9 (0x033F)";
  EXPECT_EQ((Bytes{payload[15], payload[16], payload[17], payload[18]}), (Bytes{0x0D, 0x0C, 0x0B, 0x0A}))
      << "overruns at 15";
  EXPECT_EQ(std::bit_cast<float>(static_cast<std::uint32_t>(payload[59] | payload[60] << 8 | payload[61] << 16 |
                                                            payload[62] << 24)),
            17.25f)
      << "d at 59";
  EXPECT_EQ((Bytes{payload[171], payload[172], payload[173], payload[174]}), (Bytes{0, 0, 0, 0x80}))
      << "command[0] = -0.0 at 171";
  EXPECT_EQ((Bytes{payload[203], payload[204], payload[205], payload[206], payload[207], payload[208]}),
            (Bytes{0x44, 0x33, 0x22, 0x11, 0x03, 0x00}))
      << "adapt_updates at 203, recognized_state at 207";
  EXPECT_EQ((Bytes{payload[213], payload[214]}), (Bytes{0xFF, 0xFF})) << "other_object_state (none) at 213";

  const auto reports = encode(r);
  const std::size_t lengths[4] = {56, 56, 56, 51};
  for (std::size_t part = 0; part < 4; ++part) {
    const std::uint8_t* rep = reports.data() + 64 * part;
    EXPECT_EQ(rep[0], 3) << "format version";
    EXPECT_EQ(rep[1], part);
    EXPECT_EQ(rep[2], 4);
    EXPECT_EQ(rep[3], lengths[part]);
    EXPECT_EQ((Bytes{rep[4], rep[5], rep[6], rep[7]}), (Bytes{0x04, 0x03, 0x02, 0x01})) << "sequence, LE";
    const Bytes got(rep + 8, rep + 8 + lengths[part]);
    const Bytes want(payload.begin() + static_cast<long>(56 * part),
                     payload.begin() + static_cast<long>(56 * part + lengths[part]));
    EXPECT_EQ(got, want) << "part " << part;
    for (std::size_t i = 8 + lengths[part]; i < 64; ++i) EXPECT_EQ(rep[i], 0) << "padding of part " << part;
  }
}

// One layout: the reports' payload is the link's 0x88 period result payload
// of the same record, byte for byte.
TEST(UsbTelemetry, PayloadIsThePeriodResultOfTheLink) {
  const app::PeriodRecord<Q> r = sample_record(42);
  Bytes period_result(link::PayloadSizes<Q>::kPeriodResult);
  ASSERT_EQ(link::encode_period_result<Q>(r, period_result), period_result.size());
  EXPECT_EQ(payload_of(encode(r)), period_result);
  EXPECT_EQ(L::kPayloadSize, link::PayloadSizes<Q>::kPeriodResult);
}

TEST(UsbTelemetry, DecoderRestoresTheRecordBitForBit) {
  Decoder dec;
  const app::PeriodRecord<Q> r = sample_record(7);
  const auto reports = encode(r);
  EXPECT_EQ(dec.push(std::span(reports).subspan(0, 64)), Decoder::Event::kNone);
  EXPECT_EQ(dec.push(std::span(reports).subspan(64, 64)), Decoder::Event::kNone);
  EXPECT_EQ(dec.push(std::span(reports).subspan(128, 64)), Decoder::Event::kNone);
  ASSERT_EQ(dec.push(std::span(reports).subspan(192, 64)), Decoder::Event::kRecord);
  expect_same_bits<Q>(dec.record(), r);
  EXPECT_EQ(std::bit_cast<std::uint32_t>(dec.record().prediction[5]), 0x7FC12345u);
  EXPECT_EQ(std::bit_cast<std::uint32_t>(dec.record().command[0]), 0x80000000u);
  EXPECT_EQ(dec.stats().records, 1u);
  EXPECT_EQ(dec.stats().dropped, 0u);
}

TEST(UsbTelemetry, DecoderCountsDropsFromSequenceGaps) {
  Decoder dec;
  const auto feed = [&](std::uint32_t seq, std::size_t parts = 4) {
    const auto reps = encode(sample_record(seq));
    Decoder::Event last = Decoder::Event::kNone;
    for (std::size_t p = 0; p < parts; ++p) last = dec.push(std::span(reps).subspan(64 * p, 64));
    return last;
  };
  EXPECT_EQ(feed(1), Decoder::Event::kRecord);
  EXPECT_EQ(feed(2), Decoder::Event::kRecord);
  EXPECT_EQ(feed(5), Decoder::Event::kRecord);  // 3, 4 lost: 2 drops
  EXPECT_EQ(feed(6, 3), Decoder::Event::kNone);  // last part lost
  EXPECT_EQ(feed(7), Decoder::Event::kRecord);  // 6 incomplete: 1 drop
  EXPECT_EQ(feed(7), Decoder::Event::kNone);    // duplicate
  EXPECT_EQ(feed(1), Decoder::Event::kRecord);  // device restarted
  EXPECT_EQ(feed(2), Decoder::Event::kRecord);
  const TelemetryStats& s = dec.stats();
  EXPECT_EQ(s.records, 6u);
  EXPECT_EQ(s.dropped, 3u);
  EXPECT_EQ(s.incomplete_sets, 1u);
  EXPECT_EQ(s.duplicates, 1u);
  EXPECT_EQ(s.restarts, 1u);
  EXPECT_EQ(s.bad_reports, 0u);
  EXPECT_EQ(s.bad_payloads, 0u);
}

TEST(UsbTelemetry, DecoderRejectsMalformedReportsAndOutOfOrderParts) {
  Decoder dec;
  auto reps = encode(sample_record(9));
  std::array<std::uint8_t, 64> bad{};
  std::memcpy(bad.data(), reps.data(), 64);
  bad[0] = 1;  // version 1 (the old layout)
  EXPECT_EQ(dec.push(bad), Decoder::Event::kBadReport);
  std::memcpy(bad.data(), reps.data(), 64);
  bad[2] = 5;  // part count
  EXPECT_EQ(dec.push(bad), Decoder::Event::kBadReport);
  std::memcpy(bad.data(), reps.data(), 64);
  bad[3] = 55;  // part length
  EXPECT_EQ(dec.push(bad), Decoder::Event::kBadReport);
  EXPECT_EQ(dec.push(std::span(reps).subspan(0, 63)), Decoder::Event::kBadReport);  // size
  // Parts 0, 2: part 2 out of order abandons the set.
  EXPECT_EQ(dec.push(std::span(reps).subspan(0, 64)), Decoder::Event::kNone);
  EXPECT_EQ(dec.push(std::span(reps).subspan(128, 64)), Decoder::Event::kNone);
  EXPECT_EQ(dec.stats().bad_reports, 4u);
  EXPECT_EQ(dec.stats().incomplete_sets, 1u);
  EXPECT_EQ(dec.stats().records, 0u);
}

// A whole set whose payload decode_period_result refuses (unknown mode,
// unknown flag bit, a recognized state beyond the PB table) or whose payload sequence is not the header's is not
// delivered; its sequence number counts as dropped once a later one arrives.
TEST(UsbTelemetry, DecoderRefusesASetWhosePayloadDoesNotDecode) {
  Decoder dec;
  const auto feed = [&](const std::array<std::uint8_t, kSet>& reps) {
    Decoder::Event last = Decoder::Event::kNone;
    for (std::size_t p = 0; p < L::kParts; ++p) last = dec.push(std::span(reps).subspan(64 * p, 64));
    return last;
  };
  ASSERT_EQ(feed(encode(sample_record(1))), Decoder::Event::kRecord);
  auto bad_mode = encode(sample_record(2));
  bad_mode[8 + 8] = 3;  // payload offset 8: mode
  EXPECT_EQ(feed(bad_mode), Decoder::Event::kBadReport);
  auto bad_flags = encode(sample_record(3));
  bad_flags[8 + 10] |= 0x04;  // payload offset 9..10: flags bit 10
  EXPECT_EQ(feed(bad_flags), Decoder::Event::kBadReport);
  auto bad_state = encode(sample_record(3));
  bad_state[3 * 64 + 8 + (207 - 3 * 56)] = static_cast<std::uint8_t>(Q::kStates);  // payload 207: recognized state
  EXPECT_EQ(feed(bad_state), Decoder::Event::kBadReport);
  auto bad_sequence = encode(sample_record(4));
  bad_sequence[8 + 0] ^= 1;  // payload sequence 5, header 4
  EXPECT_EQ(feed(bad_sequence), Decoder::Event::kBadReport);
  EXPECT_EQ(dec.record().sequence, 1u) << "the last delivered record stays";
  ASSERT_EQ(feed(encode(sample_record(5))), Decoder::Event::kRecord);
  expect_same_bits<Q>(dec.record(), sample_record(5));
  EXPECT_EQ(dec.stats().bad_payloads, 4u);
  EXPECT_EQ(dec.stats().bad_reports, 0u);
  EXPECT_EQ(dec.stats().dropped, 3u) << "2, 3 and 4 never delivered";
  EXPECT_EQ(dec.stats().records, 2u);
}

}  // namespace
}  // namespace hadynet::usb
