// The HID telemetry wire format (telemetry_report.h) and the host decoder
// (telemetry_decoder.h). Layout checks compare with bytes assembled here by
// hand from docs/usb.md's offsets (not with the encoder); floats travel as
// their bit patterns, so every comparison is exact.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>

#include "firmware/usb/telemetry_decoder.h"
#include "firmware/usb/telemetry_report.h"
#include "hadynet_model_q15.h"

namespace hadynet::usb {
namespace {

using Q = model_q15::Model;
using Bytes = std::vector<std::uint8_t>;
using L = TelemetryLayout<Q>;
constexpr std::size_t kSet = L::kParts * kTelemetryReportSize;

TelemetryRecord<Q> sample_record(std::uint32_t sequence) {
  TelemetryRecord<Q> r;
  r.sequence = sequence;
  r.period = 1000 + sequence;
  r.mode = 2;
  r.flags = kTelemetryPredictionValid | kTelemetryDistanceValid | kTelemetryContact | kTelemetryOverrun;
  r.d = 17.25f;
  for (int i = 0; i < Q::kY; ++i) r.prediction[i] = 0.5f * static_cast<float>(i) - 3.0f;
  for (int i = 0; i < Q::kU; ++i) r.command[i] = -1.0f / static_cast<float>(i + 1);
  r.command[0] = -0.0f;  // a sign bit only the bit pattern keeps
  return r;
}

std::array<std::uint8_t, kSet> encode(const TelemetryRecord<Q>& r) {
  std::array<std::uint8_t, kSet> out{};
  encode_telemetry_reports<Q>(r, out);
  return out;
}

void put32(Bytes& b, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

TEST(UsbTelemetry, TheHandsModelNeedsThreeReports) {
  // kY 27, kU 8: 12 + 4 * 35 = 152 payload bytes, 56 per report.
  EXPECT_EQ(Q::kY, 27);
  EXPECT_EQ(Q::kU, 8);
  EXPECT_EQ(L::kPayloadSize, 152u);
  EXPECT_EQ(L::kParts, 3u);
}

TEST(UsbTelemetry, ReportBytesFollowTheDocumentedLayout) {
  const TelemetryRecord<Q> r = sample_record(0x01020304);
  // The payload assembled by hand: period u32, mode u8, reserved u8, flags
  // u16, d f32, prediction[kY] f32, command[kU] f32, little-endian.
  Bytes payload;
  put32(payload, r.period);
  payload.push_back(2);
  payload.push_back(0);
  payload.push_back(static_cast<std::uint8_t>(r.flags));
  payload.push_back(static_cast<std::uint8_t>(r.flags >> 8));
  put32(payload, std::bit_cast<std::uint32_t>(r.d));
  for (const float v : r.prediction) put32(payload, std::bit_cast<std::uint32_t>(v));
  for (const float v : r.command) put32(payload, std::bit_cast<std::uint32_t>(v));
  ASSERT_EQ(payload.size(), 152u);

  const auto reports = encode(r);
  const std::size_t lengths[3] = {56, 56, 40};
  for (std::size_t part = 0; part < 3; ++part) {
    const std::uint8_t* rep = reports.data() + 64 * part;
    EXPECT_EQ(rep[0], 1) << "format version";
    EXPECT_EQ(rep[1], part);
    EXPECT_EQ(rep[2], 3);
    EXPECT_EQ(rep[3], lengths[part]);
    EXPECT_EQ((Bytes{rep[4], rep[5], rep[6], rep[7]}), (Bytes{0x04, 0x03, 0x02, 0x01})) << "sequence, LE";
    const Bytes got(rep + 8, rep + 8 + lengths[part]);
    const Bytes want(payload.begin() + static_cast<long>(56 * part),
                     payload.begin() + static_cast<long>(56 * part + lengths[part]));
    EXPECT_EQ(got, want) << "part " << part;
    for (std::size_t i = 8 + lengths[part]; i < 64; ++i) EXPECT_EQ(rep[i], 0) << "padding of part " << part;
  }
}

TEST(UsbTelemetry, DecoderRestoresTheRecordBitForBit) {
  TelemetryDecoder<Q> dec;
  const TelemetryRecord<Q> r = sample_record(7);
  const auto reports = encode(r);
  EXPECT_EQ(dec.push(std::span(reports).subspan(0, 64)), TelemetryDecoder<Q>::Event::kNone);
  EXPECT_EQ(dec.push(std::span(reports).subspan(64, 64)), TelemetryDecoder<Q>::Event::kNone);
  ASSERT_EQ(dec.push(std::span(reports).subspan(128, 64)), TelemetryDecoder<Q>::Event::kRecord);
  const TelemetryRecord<Q>& d = dec.record();
  EXPECT_EQ(d.sequence, 7u);
  EXPECT_EQ(d.period, r.period);
  EXPECT_EQ(d.mode, r.mode);
  EXPECT_EQ(d.flags, r.flags);
  EXPECT_EQ(std::memcmp(&d.d, &r.d, 4), 0);
  EXPECT_EQ(std::memcmp(d.prediction, r.prediction, sizeof(r.prediction)), 0);
  EXPECT_EQ(std::memcmp(d.command, r.command, sizeof(r.command)), 0);
  EXPECT_EQ(dec.stats().records, 1u);
  EXPECT_EQ(dec.stats().dropped, 0u);
}

TEST(UsbTelemetry, DecoderCountsDropsFromSequenceGaps) {
  TelemetryDecoder<Q> dec;
  const auto feed = [&](std::uint32_t seq, std::size_t parts = 3) {
    const auto reps = encode(sample_record(seq));
    TelemetryDecoder<Q>::Event last = TelemetryDecoder<Q>::Event::kNone;
    for (std::size_t p = 0; p < parts; ++p) last = dec.push(std::span(reps).subspan(64 * p, 64));
    return last;
  };
  EXPECT_EQ(feed(1), TelemetryDecoder<Q>::Event::kRecord);
  EXPECT_EQ(feed(2), TelemetryDecoder<Q>::Event::kRecord);
  EXPECT_EQ(feed(5), TelemetryDecoder<Q>::Event::kRecord);  // 3, 4 lost: 2 drops
  EXPECT_EQ(feed(6, 2), TelemetryDecoder<Q>::Event::kNone);  // last part lost
  EXPECT_EQ(feed(7), TelemetryDecoder<Q>::Event::kRecord);  // 6 incomplete: 1 drop
  EXPECT_EQ(feed(7), TelemetryDecoder<Q>::Event::kNone);    // duplicate
  EXPECT_EQ(feed(1), TelemetryDecoder<Q>::Event::kRecord);  // device restarted
  EXPECT_EQ(feed(2), TelemetryDecoder<Q>::Event::kRecord);
  const TelemetryStats& s = dec.stats();
  EXPECT_EQ(s.records, 6u);
  EXPECT_EQ(s.dropped, 3u);
  EXPECT_EQ(s.incomplete_sets, 1u);
  EXPECT_EQ(s.duplicates, 1u);
  EXPECT_EQ(s.restarts, 1u);
  EXPECT_EQ(s.bad_reports, 0u);
}

TEST(UsbTelemetry, DecoderRejectsMalformedReportsAndOutOfOrderParts) {
  TelemetryDecoder<Q> dec;
  auto reps = encode(sample_record(9));
  std::array<std::uint8_t, 64> bad{};
  std::memcpy(bad.data(), reps.data(), 64);
  bad[0] = 2;  // version
  EXPECT_EQ(dec.push(bad), TelemetryDecoder<Q>::Event::kBadReport);
  std::memcpy(bad.data(), reps.data(), 64);
  bad[2] = 4;  // part count
  EXPECT_EQ(dec.push(bad), TelemetryDecoder<Q>::Event::kBadReport);
  std::memcpy(bad.data(), reps.data(), 64);
  bad[3] = 55;  // part length
  EXPECT_EQ(dec.push(bad), TelemetryDecoder<Q>::Event::kBadReport);
  EXPECT_EQ(dec.push(std::span(reps).subspan(0, 63)), TelemetryDecoder<Q>::Event::kBadReport);  // size
  // Parts 0, 2: part 2 out of order abandons the set.
  EXPECT_EQ(dec.push(std::span(reps).subspan(0, 64)), TelemetryDecoder<Q>::Event::kNone);
  EXPECT_EQ(dec.push(std::span(reps).subspan(128, 64)), TelemetryDecoder<Q>::Event::kNone);
  EXPECT_EQ(dec.stats().bad_reports, 4u);
  EXPECT_EQ(dec.stats().incomplete_sets, 1u);
  EXPECT_EQ(dec.stats().records, 0u);
}

}  // namespace
}  // namespace hadynet::usb
