// Frames (header, length, CRC, version), message payload codecs, and the
// byte-at-a-time stream decoder with its hard size limit. All checks are
// exact: the decoder either delivers the sent bytes or reports the error.
#include "firmware/link/stream_decoder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "firmware/link/frame.h"
#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "hadynet_model_q15.h"

namespace hadynet::link {
namespace {

using Bytes = std::vector<std::uint8_t>;
using Q = model_q15::Model;

Bytes make_frame(std::uint8_t version, std::uint8_t type, std::uint16_t seq, const Bytes& payload) {
  Bytes frame(kMaxFrame);
  FrameBuilder b(frame);
  std::copy(payload.begin(), payload.end(), b.payload().begin());
  frame.resize(b.finish_raw(version, type, seq, payload.size()));
  return frame;
}

TEST(LinkFrame, LayoutIsLittleEndianWithTrailingCrc) {
  const Bytes f = make_frame(1, 0x02, 0x1234, {0xAA, 0xBB, 0xCC});
  ASSERT_EQ(f.size(), kFrameOverhead + 3);
  EXPECT_EQ(f[0], 1);
  EXPECT_EQ(f[1], 0x02);
  EXPECT_EQ(f[2], 0x34);  // sequence, LE
  EXPECT_EQ(f[3], 0x12);
  EXPECT_EQ(f[4], 3);  // payload length, LE
  EXPECT_EQ(f[5], 0);
  EXPECT_EQ(f[6], 0xAA);
  const std::uint32_t crc = crc32(std::span<const std::uint8_t>(f).first(9));
  EXPECT_EQ(f[9], crc & 0xFF);
  EXPECT_EQ(f[12], crc >> 24);

  Frame parsed;
  ASSERT_TRUE(parse_frame(f, parsed).ok());
  EXPECT_EQ(parsed.type, 0x02);
  EXPECT_EQ(parsed.sequence, 0x1234);
  EXPECT_EQ(Bytes(parsed.payload.begin(), parsed.payload.end()), (Bytes{0xAA, 0xBB, 0xCC}));
}

TEST(LinkFrame, ParseReportsEachDefect) {
  const Bytes good = make_frame(1, 0x04, 77, {0x01});
  Frame f;
  // Shorter than header + CRC, and shorter than the length field says.
  for (std::size_t n : {0u, 1u, 6u, 9u, 10u}) {
    EXPECT_EQ(parse_frame(std::span<const std::uint8_t>(good).first(n), f).code, ErrorCode::kTruncated) << n;
    EXPECT_EQ(f.sequence, 0);
  }
  Bytes longer = good;
  longer.push_back(0x00);
  EXPECT_EQ(parse_frame(longer, f).code, ErrorCode::kBadPayloadLength);
  for (std::size_t i = 0; i < good.size(); ++i) {
    if (i == 4 || i == 5) continue;  // the length field: a size defect instead
    Bytes bad = good;
    bad[i] ^= 0x10;
    EXPECT_EQ(parse_frame(bad, f).code, ErrorCode::kBadCrc) << "byte " << i;
    EXPECT_EQ(f.sequence, 0) << "an unchecked sequence number is not reported";
  }
  const Bytes v2 = make_frame(2, 0x04, 77, {0x01});
  EXPECT_EQ(parse_frame(v2, f).code, ErrorCode::kBadVersion);
  EXPECT_EQ(f.sequence, 77) << "the CRC checked, so the sequence number is known";
}

TEST(LinkFrame, BuilderRejectsOversizedPayloads) {
  Bytes frame(kMaxFrame);
  FrameBuilder b(frame);
  EXPECT_EQ(b.payload().size(), kMaxPayload);
  EXPECT_EQ(b.finish(MessageType::kInfo, 1, kMaxPayload + 1), 0u);
  EXPECT_EQ(b.finish(MessageType::kInfo, 1, kMaxPayload), kMaxFrame);
  Bytes tiny(5);
  EXPECT_TRUE(FrameBuilder(tiny).payload().empty());
  EXPECT_EQ(FrameBuilder(tiny).finish(MessageType::kInfo, 1, 0), 0u);
}

TEST(LinkMessages, RoundTrips) {
  Bytes buf(kMaxPayload);

  const InfoReply info = info_of<Q>();
  InfoReply info_back;
  const std::size_t n_info = encode_info(info, buf);
  ASSERT_GT(n_info, 0u);
  EXPECT_LE(n_info, kInfoPayloadMax);
  ASSERT_TRUE(decode_info(std::span<const std::uint8_t>(buf).first(n_info), info_back));
  EXPECT_EQ(info_back.model_hash, Q::kModelHash);
  EXPECT_STREQ(info_back.generator_version, Q::kGeneratorVersion);
  EXPECT_FALSE(decode_info(std::span<const std::uint8_t>(buf).first(n_info - 1), info_back));

  firmware::StepResult<Q> r;
  r.prediction_valid = true;
  r.contact = true;
  r.d = 17.5f;
  for (int i = 0; i < Q::kY; ++i) r.prediction[i] = static_cast<float>(i) - 0.25f;
  r.command[3] = -std::numeric_limits<float>::infinity();
  const std::size_t n_step = encode_step_result<Q>(r, buf);
  ASSERT_EQ(n_step, PayloadSizes<Q>::kStepResult);
  EXPECT_EQ(buf[0], kFlagPredictionValid | kFlagContact);
  firmware::StepResult<Q> back;
  ASSERT_TRUE(decode_step_result<Q>(std::span<const std::uint8_t>(buf).first(n_step), back));
  EXPECT_TRUE(back.prediction_valid && back.contact && !back.distance_valid && !back.command_valid);
  EXPECT_EQ(std::memcmp(back.prediction, r.prediction, sizeof r.prediction), 0);
  EXPECT_EQ(std::memcmp(back.command, r.command, sizeof r.command), 0);
  EXPECT_EQ(back.d, 17.5f);

  // Reasons are cut at kMaxReason bytes.
  const std::string long_reason(100, 'x');
  const std::size_t n_err = encode_error(ErrorCode::kBadValue, 513, long_reason.c_str(), buf);
  EXPECT_EQ(n_err, kErrorPayloadMax);
  ErrorReply e;
  ASSERT_TRUE(decode_error(std::span<const std::uint8_t>(buf).first(n_err), e));
  EXPECT_EQ(e.code, ErrorCode::kBadValue);
  EXPECT_EQ(e.sequence, 513);
  EXPECT_EQ(std::string(e.reason), std::string(kMaxReason, 'x'));
}

// ---- stream decoder

struct Fed {
  std::vector<StreamDecoder::Event> events;  // every event other than kNone
  std::vector<Bytes> frames;
};

Fed feed(StreamDecoder& d, const Bytes& wire) {
  Fed out;
  for (std::uint8_t b : wire) {
    const auto ev = d.push(b);
    EXPECT_LE(d.pending(), kMaxEncodedFrame) << "buffered beyond the hard maximum";
    if (ev == StreamDecoder::Event::kNone) continue;
    out.events.push_back(ev);
    if (ev == StreamDecoder::Event::kFrame) out.frames.emplace_back(d.frame().begin(), d.frame().end());
  }
  return out;
}

Bytes wire_of(const Bytes& decoded) {
  Bytes wire(kMaxWireFrame + 32);
  wire.resize(encode_for_wire(decoded, wire));
  return wire;
}

TEST(LinkStreamDecoder, DeliversFramesAndSkipsEmptyOnes) {
  const Bytes a = make_frame(1, 0x01, 1, {});
  const Bytes b = make_frame(1, 0x04, 2, {0x00});
  Bytes wire = {0x00, 0x00};  // leading delimiters
  for (const Bytes& f : {a, b}) {
    const Bytes w = wire_of(f);
    wire.insert(wire.end(), w.begin(), w.end());
    wire.push_back(0x00);  // an extra delimiter between frames
  }
  StreamDecoder d;
  const Fed fed = feed(d, wire);
  ASSERT_EQ(fed.events.size(), 2u);
  EXPECT_EQ(fed.frames, (std::vector<Bytes>{a, b}));
  EXPECT_EQ(d.pending(), 0u);
}

TEST(LinkStreamDecoder, AcceptsExactlyTheMaximumAndDropsLongerFramesUnbuffered) {
  // An encoded frame of exactly kMaxEncodedFrame bytes is accepted.
  const Bytes decoded_max(kMaxEncodedFrame - 1, 0x00);  // n zeros encode into n + 1 bytes
  Bytes wire = wire_of(decoded_max);
  ASSERT_EQ(wire.size(), kMaxEncodedFrame + 1);
  StreamDecoder d;
  Fed fed = feed(d, wire);
  ASSERT_EQ(fed.frames.size(), 1u);
  EXPECT_EQ(fed.frames[0], decoded_max);

  // One byte more: reported once, at that byte; the rest up to the next
  // delimiter is dropped; the next frame is received normally.
  for (std::size_t extra : {1u, 2u, 1000u}) {
    Bytes over(kMaxEncodedFrame + extra, 0x01);  // 0x01: empty blocks, each decodes to a zero
    std::vector<StreamDecoder::Event> events;
    for (std::size_t i = 0; i < over.size(); ++i) {
      const auto ev = d.push(over[i]);
      if (ev != StreamDecoder::Event::kNone) {
        events.push_back(ev);
        EXPECT_EQ(i, kMaxEncodedFrame) << "reported at the first byte beyond the maximum";
      }
      EXPECT_LE(d.pending(), kMaxEncodedFrame);
    }
    ASSERT_EQ(events, std::vector<StreamDecoder::Event>{StreamDecoder::Event::kOversize});
    EXPECT_TRUE(d.dropping());
    EXPECT_EQ(d.push(0x00), StreamDecoder::Event::kNone) << "the delimiter ends the dropped frame silently";
    const Bytes next = make_frame(1, 0x05, 9, {});
    fed = feed(d, wire_of(next));
    ASSERT_EQ(fed.frames.size(), 1u) << "extra " << extra;
    EXPECT_EQ(fed.frames[0], next);
  }
}

TEST(LinkStreamDecoder, ReportsACutCobsBlock) {
  StreamDecoder d;
  const Fed fed = feed(d, Bytes{0x05, 0x11, 0x22, 0x00});
  EXPECT_EQ(fed.events, std::vector<StreamDecoder::Event>{StreamDecoder::Event::kBadEncoding});
  const Bytes next = make_frame(1, 0x01, 3, {});
  const Fed after = feed(d, wire_of(next));
  ASSERT_EQ(after.frames.size(), 1u);
  EXPECT_EQ(after.frames[0], next);
}

TEST(LinkClient, NumbersRequestsAndAdvancesOnSuccessReplies) {
  LinkClient<Q> client;
  client.set_next_sequence(65535);
  Bytes wire(kMaxWireFrame);
  const std::size_t n = client.set_mode(firmware::Mode::kControl, wire);
  ASSERT_GT(n, 0u);
  StreamDecoder d;
  const Fed fed = feed(d, Bytes(wire.begin(), wire.begin() + static_cast<std::ptrdiff_t>(n)));
  ASSERT_EQ(fed.frames.size(), 1u);
  Frame f;
  ASSERT_TRUE(parse_frame(fed.frames[0], f).ok());
  EXPECT_EQ(f.type, 0x04);
  EXPECT_EQ(f.sequence, 65535);
  EXPECT_EQ(Bytes(f.payload.begin(), f.payload.end()), Bytes{2});

  // An error reply does not advance; the ack to 65535 does (wrapping to 0).
  const Bytes error = make_frame(1, 0x7F, 65535, {});
  EXPECT_FALSE(client.accept(error).ok());
  EXPECT_EQ(client.next_sequence(), 65535);
  const Bytes stale_ack = make_frame(1, 0x84, 1234, {});
  EXPECT_TRUE(client.accept(stale_ack).ok());
  EXPECT_EQ(client.next_sequence(), 65535);
  const Bytes ack = make_frame(1, 0x84, 65535, {});
  EXPECT_TRUE(client.accept(ack).ok());
  EXPECT_EQ(client.next_sequence(), 0);
  const Bytes request_type = make_frame(1, 0x04, 0, {});
  EXPECT_EQ(client.accept(request_type).status.code, ErrorCode::kUnknownType);
}

}  // namespace
}  // namespace hadynet::link
