// Malformed input on the link (docs/architecture.md §6, issue 5): every bad frame gets
// the right error reply and changes nothing. Proof by twins: device A gets
// the bad frame, device B never sees it; afterwards A's runtime is byte for
// byte B's (history, network state, plan, PB, mode), the link's sequence
// state is B's, and the next valid sensor frame gives both the identical
// reply frame (exact: same code, same inputs, so tolerance zero).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "hadynet_model_q15.h"
#include "link_test_device.h"

namespace hadynet::link {
namespace {

using namespace hadynet::link::testing;
using Q = model_q15::Model;
using firmware::Mode;

Bytes f32_bytes(std::initializer_list<float> values) {
  Bytes b;
  for (float v : values) {
    const auto u = std::bit_cast<std::uint32_t>(v);
    for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(u >> (8 * k)));
  }
  return b;
}

Bytes sensor_payload(int t) {
  Bytes p(PayloadSizes<Q>::kSensorFrame);
  encode_sensor_frame<Q>(synthetic_frame<Q>(t), p);
  return p;
}

Bytes pb_values_payload(float bad, int at) {
  Bytes p = {1};
  for (int i = 0; i < Q::kPb; ++i) {
    const Bytes v = f32_bytes({i == at ? bad : 0.25f * static_cast<float>(i)});
    p.insert(p.end(), v.begin(), v.end());
  }
  return p;
}

ErrorCode decode_error_code(const Bytes& reply) {
  const Reply r = parse_reply(reply);
  ErrorReply e;
  if (r.type != MessageType::kError || !decode_error(r.payload, e)) return ErrorCode::kNone;
  return e.code;
}

struct BadInput {
  std::string name;
  Bytes wire;           // exactly what goes on the wire (incl. delimiters)
  ErrorCode code;       // the error reply's code
  bool sequence_known;  // the reply echoes the request's number (else 0)
};

// A well-formed request (right version, CRC and sequence number) whose
// payload is wrong.
struct BadRequest {
  std::string name;
  std::uint8_t type;
  Bytes payload;
};

// Two devices driven in lockstep with valid traffic; bad input to A only.
class LinkRobustness : public ::testing::Test {
 protected:
  void SetUp() override {
    // Warm up into control mode with a full history (the largest state),
    // PB from the table; the sequence starts at 1000.
    client_.set_next_sequence(1000);
    exchange_both([&](auto w) { return client_.set_pb_state(1, w); });
    exchange_both([&](auto w) { return client_.set_mode(Mode::kControl, w); });
    for (int t = 0; t < Q::kDetectSteps + 3; ++t) {
      exchange_both([&](auto w) { return client_.sensor_frame(synthetic_frame<Q>(t), w); });
    }
    next_t_ = Q::kDetectSteps + 3;
  }

  template <class F>
  void exchange_both(F&& build) {
    const Bytes wire = wire_of(build);
    const Bytes ra = a_.send_one(wire);
    const Bytes rb = b_.send_one(wire);
    EXPECT_EQ(ra, rb);
    const Reply r = client_.accept(ra);
    EXPECT_TRUE(r.ok()) << "valid request refused";
  }

  // The decoded request frame for the current sequence number.
  std::uint16_t seq() const { return client_.next_sequence(); }
  Bytes frame(std::uint8_t type, const Bytes& payload) const { return make_frame(1, type, seq(), payload); }

  // Sends `bad` to A only and checks the reply and that nothing changed.
  void expect_rejected(const BadInput& bad) {
    SCOPED_TRACE(bad.name);
    const std::vector<Bytes> replies = a_.send(bad.wire);
    ASSERT_EQ(replies.size(), 1u) << "exactly one reply per bad frame";
    const Reply r = parse_reply(replies[0]);
    ASSERT_TRUE(r.status.ok()) << "the error reply is itself a valid frame";
    ASSERT_EQ(r.type, MessageType::kError);
    ErrorReply e;
    ASSERT_TRUE(decode_error(r.payload, e));
    EXPECT_EQ(e.code, bad.code) << e.reason;
    const std::uint16_t echoed = bad.sequence_known ? seq() : 0;
    EXPECT_EQ(e.sequence, echoed);
    EXPECT_EQ(r.sequence, echoed);
    EXPECT_GT(e.reason_size, 0u);
    expect_same_state(a_, b_);
    // The next valid sensor frame: identical replies from both.
    exchange_both([&](auto w) { return client_.sensor_frame(synthetic_frame<Q>(next_t_), w); });
    ++next_t_;
    expect_same_state(a_, b_);
  }

  ZeroedDevice<Q> a_, b_;
  LinkClient<Q> client_;
  int next_t_ = 0;
};

TEST_F(LinkRobustness, TruncatedFrames) {
  const Bytes good = frame(0x02, sensor_payload(50));
  for (std::size_t keep :
       {std::size_t{0} + 1, std::size_t{5}, std::size_t{9}, std::size_t{10}, good.size() / 2, good.size() - 1}) {
    const Bytes cut(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(keep));
    expect_rejected({"first " + std::to_string(keep) + " bytes", encode_wire(cut), ErrorCode::kTruncated, false});
  }
  // An encoded frame whose last COBS block is cut short.
  Bytes wire = encode_wire(good);
  wire.erase(wire.end() - 2);  // drop the last encoded byte, keep the delimiter
  expect_rejected({"COBS block cut short", wire, ErrorCode::kTruncated, false});
  // Only a code byte: decodes to nothing.
  expect_rejected({"empty decoded frame", Bytes{0x01, 0x00}, ErrorCode::kTruncated, false});
}

TEST_F(LinkRobustness, BadCrc) {
  const Bytes good = frame(0x02, sensor_payload(51));
  for (std::size_t i :
       {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{8}, good.size() - 5, good.size() - 1}) {
    Bytes bad = good;
    bad[i] ^= 0x01;
    expect_rejected({"bit flipped in byte " + std::to_string(i), encode_wire(bad), ErrorCode::kBadCrc, false});
  }
}

TEST_F(LinkRobustness, OversizeFrames) {
  expect_rejected({"600 bytes of noise", Bytes(600, 0x5A) + Bytes{0x00}, ErrorCode::kOversize, false});
  // Exactly one byte over the hard limit.
  expect_rejected({"513 encoded bytes", Bytes(kMaxEncodedFrame + 1, 0x01) + Bytes{0x00}, ErrorCode::kOversize, false});
  // A well-formed frame that is simply too large.
  Bytes big_payload(kMaxEncodedFrame, 0x33);
  expect_rejected(
      {"valid frame, 512-byte payload", encode_wire(frame(0x02, big_payload)), ErrorCode::kOversize, false});
  // A long run without delimiter: one reply at the 513th byte, nothing
  // buffered beyond the limit, the delimiter ends the dropped frame silently.
  const std::vector<Bytes> replies = a_.send(Bytes(3000, 0x77));
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(decode_error_code(replies[0]), ErrorCode::kOversize);
  EXPECT_EQ(a_->link.decoder().pending(), kMaxEncodedFrame);
  EXPECT_TRUE(a_->link.decoder().dropping());
  EXPECT_TRUE(a_.send(Bytes{0x00}).empty());
  expect_same_state(a_, b_);
  exchange_both([&](auto w) { return client_.sensor_frame(synthetic_frame<Q>(next_t_++), w); });
}

TEST_F(LinkRobustness, UnknownTypes) {
  for (int type : {0x00, 0x0A, 0x42, 0x7E, 0x7F, 0x80, 0x81, 0x82, 0x85, 0x86, 0x88, 0x89, 0xFF}) {
    expect_rejected({"type " + std::to_string(type), encode_wire(frame(static_cast<std::uint8_t>(type), {})),
                     ErrorCode::kUnknownType, true});
  }
}

TEST_F(LinkRobustness, BadVersion) {
  for (int version : {0, 2, 0xFF}) {
    expect_rejected({"version " + std::to_string(version),
                     encode_wire(make_frame(static_cast<std::uint8_t>(version), 0x02, seq(), sensor_payload(52))),
                     ErrorCode::kBadVersion, true});
  }
}

TEST_F(LinkRobustness, BadPayloadLengths) {
  Bytes sensor = sensor_payload(53);
  const Bytes short_sensor(sensor.begin(), sensor.end() - 1);
  const Bytes long_sensor = sensor + Bytes{0x00};
  const Bytes short_pb = [] {
    Bytes p = pb_values_payload(0.0f, 0);
    p.pop_back();
    return p;
  }();
  const std::vector<BadRequest> cases = {
      {"sensor frame one byte short", 0x02, short_sensor},
      {"sensor frame one byte long", 0x02, long_sensor},
      {"sensor frame empty", 0x02, {}},
      {"info request with payload", 0x01, {0x00}},
      {"reset with payload", 0x05, {0x01, 0x02}},
      {"set mode empty", 0x04, {}},
      {"set mode two bytes", 0x04, {0x01, 0x01}},
      {"set PB empty", 0x03, {}},
      {"set PB state too long", 0x03, {0x00, 0x01, 0x00, 0x00}},
      {"set PB values short", 0x03, short_pb},
      {"adapt empty", 0x09, {}},
      {"adapt two bytes", 0x09, {0x01, 0x00}},
      {"adapt four bytes", 0x09, {0x01, 0x00, 0x00, 0x00}},
  };
  for (const BadRequest& c : cases) {
    // Built now: the expected sequence number advances after each case.
    expect_rejected({c.name, encode_wire(frame(c.type, c.payload)), ErrorCode::kBadPayloadLength, true});
  }
  expect_rejected({"frame longer than its length field", encode_wire(frame(0x02, sensor) + Bytes{0xEE}),
                   ErrorCode::kBadPayloadLength, false});
}

TEST_F(LinkRobustness, BadValues) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const auto u16 = [](std::uint16_t v) {
    return Bytes{static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8)};
  };
  const std::vector<BadRequest> cases = {
      {"PB state = kStates", 0x03, Bytes{0} + u16(Q::kStates)},
      {"PB state 0xFFFF", 0x03, Bytes{0} + u16(0xFFFF)},
      {"PB NaN first", 0x03, pb_values_payload(nan, 0)},
      {"PB +inf last", 0x03, pb_values_payload(inf, Q::kPb - 1)},
      {"PB -inf middle", 0x03, pb_values_payload(-inf, Q::kPb / 2)},
      {"PB signalling NaN", 0x03, pb_values_payload(std::numeric_limits<float>::signaling_NaN(), 1)},
      {"PB kind 2", 0x03, {0x02, 0x00, 0x00}},
      {"mode 3", 0x04, {0x03}},
      {"mode 255", 0x04, {0xFF}},
      {"adapt action 4", 0x09, {0x04, 0x00, 0x00}},
      {"adapt stride beyond the windows held", 0x09, {0x01, 0xFF, 0x00}},
      {"adapt windows per period beyond the windows held", 0x09, {0x01, 0x00, 0xFF}},
  };
  for (const BadRequest& c : cases) {
    expect_rejected({c.name, encode_wire(frame(c.type, c.payload)), ErrorCode::kBadValue, true});
  }
}

TEST_F(LinkRobustness, OutOfOrderSequenceNumbers) {
  // Every request type but reset is checked; the reply echoes the offending
  // number and names the expected one.
  const std::vector<std::pair<std::uint8_t, Bytes>> requests = {
      {0x01, {}}, {0x02, sensor_payload(54)}, {0x03, {0x00, 0x00, 0x00}}, {0x04, {0x01}}};
  for (const auto& [type, payload] : requests) {
    for (int delta : {1, 2, -1, 0x8000}) {
      SCOPED_TRACE("type " + std::to_string(type) + " delta " + std::to_string(delta));
      const auto wrong = static_cast<std::uint16_t>(seq() + delta);
      const std::vector<Bytes> replies = a_.send(encode_wire(make_frame(1, type, wrong, payload)));
      ASSERT_EQ(replies.size(), 1u);
      const Reply r = parse_reply(replies[0]);
      ASSERT_EQ(r.type, MessageType::kError);
      EXPECT_EQ(r.sequence, wrong);
      ErrorReply e;
      ASSERT_TRUE(decode_error(r.payload, e));
      EXPECT_EQ(e.code, ErrorCode::kOutOfOrder);
      EXPECT_EQ(e.sequence, wrong) << "the offending frame's number";
      EXPECT_EQ(std::string(e.reason), "out of order: expected " + std::to_string(seq()));
      expect_same_state(a_, b_);
    }
    exchange_both([&](auto w) { return client_.sensor_frame(synthetic_frame<Q>(next_t_++), w); });
  }
}

// A barrage of every kind of bad input, back to back on one stream, then a
// long valid run in control mode: still identical to the twin.
TEST_F(LinkRobustness, BarrageThenIdenticalResults) {
  Bytes wire;
  const auto add = [&](const Bytes& w) { wire.insert(wire.end(), w.begin(), w.end()); };
  Bytes crc_bad = frame(0x04, {0x00});
  crc_bad.back() ^= 0x80;
  add(encode_wire(crc_bad));
  add(Bytes(2000, 0x11));
  add({0x00, 0x00, 0x00});
  add(encode_wire(frame(0x7F, {})));
  add(encode_wire(frame(0x03, pb_values_payload(std::numeric_limits<float>::quiet_NaN(), 3))));
  add(encode_wire(make_frame(1, 0x04, static_cast<std::uint16_t>(seq() + 1), {0x00})));
  add(encode_wire(make_frame(3, 0x05, seq(), {})));
  add({0x03, 0x44, 0x00});
  const std::vector<Bytes> replies = a_.send(wire);
  EXPECT_EQ(replies.size(), 7u);
  for (const Bytes& r : replies) EXPECT_EQ(parse_reply(r).type, MessageType::kError);
  expect_same_state(a_, b_);
  for (int k = 0; k < 6; ++k) {
    exchange_both([&](auto w) { return client_.sensor_frame(synthetic_frame<Q>(next_t_++), w); });
  }
  expect_same_state(a_, b_);
}

// Before the first executed request the device accepts any number; a
// malformed first request does not synchronise it.
TEST(LinkRobustnessFresh, MalformedFirstRequestLeavesTheDeviceUnsynchronised) {
  ZeroedDevice<Q> a;
  const std::vector<Bytes> replies = a.send(encode_wire(make_frame(1, 0x04, 500, {0x07})));
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(parse_reply(replies[0]).type, MessageType::kError);
  EXPECT_FALSE(a->link.dispatcher().synchronised());
  const Bytes ack = a.send_one(encode_wire(make_frame(1, 0x04, 9, {0x00})));
  EXPECT_EQ(parse_reply(ack).type, MessageType::kSetModeAck);
  EXPECT_EQ(a->link.dispatcher().expected_sequence(), 10);
}

}  // namespace
}  // namespace hadynet::link
