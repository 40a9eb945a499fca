// CDC-ACM: the class requests, and the link protocol carried over bulk
// endpoints. The link check is differential and exact: the same request
// bytes go (a) over USB into the composite device's DeviceLink and (b) byte
// by byte into a twin DeviceLink with its own runtime; the bytes read from
// bulk IN must equal the twin's output byte for byte (the link is bits; any
// loss, reordering or duplication in the USB path shows).
#include <gtest/gtest.h>

#include <cmath>

#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "firmware/link/stream_decoder.h"
#include "usb_test_device.h"

namespace hadynet::usb::testing {
namespace {

constexpr std::uint8_t kComm = composite::kCdcCommInterface;

SetupPacket cdc_req(bool in, std::uint8_t request, std::uint16_t value, std::uint16_t length,
                    std::uint8_t interface = kComm) {
  return UsbTestDevice::class_interface(in, request, value, interface, length);
}

TEST(UsbCdc, LineCodingRoundTripsAndInvalidCodingsStall) {
  UsbTestDevice dev;
  dev.enumerate();
  Bytes in;
  ASSERT_TRUE(dev.control(cdc_req(true, cdc::kGetLineCoding, 0, 7), {}, &in).ok());
  EXPECT_EQ(in, (Bytes{0x00, 0xC2, 0x01, 0x00, 0, 0, 8})) << "default 115200 8N1";
  const Bytes coding_9600_7e2 = {0x80, 0x25, 0x00, 0x00, 2, 2, 7};
  ASSERT_TRUE(dev.control(cdc_req(false, cdc::kSetLineCoding, 0, 7), coding_9600_7e2).ok());
  ASSERT_TRUE(dev.control(cdc_req(true, cdc::kGetLineCoding, 0, 7), {}, &in).ok());
  EXPECT_EQ(in, coding_9600_7e2);
  EXPECT_EQ(dev.usb->cdc().line_coding().baud, 9600u);
  // Refused (STALL in the status stage), coding unchanged: 9 data bits,
  // parity 5, stop bits 3, baud 0.
  for (const Bytes& bad : {Bytes{0x80, 0x25, 0, 0, 0, 0, 9}, Bytes{0x80, 0x25, 0, 0, 0, 5, 8},
                           Bytes{0x80, 0x25, 0, 0, 3, 0, 8}, Bytes{0, 0, 0, 0, 0, 0, 8}}) {
    const ControlResult r = dev.control(cdc_req(false, cdc::kSetLineCoding, 0, 7), bad);
    EXPECT_TRUE(r.stalled());
    EXPECT_EQ(r.stage, ControlResult::Stage::kStatus);
  }
  ASSERT_TRUE(dev.control(cdc_req(true, cdc::kGetLineCoding, 0, 7), {}, &in).ok());
  EXPECT_EQ(in, coding_9600_7e2);
  // Wrong lengths and the wrong interface: STALL at the setup stage.
  EXPECT_TRUE(dev.control(cdc_req(false, cdc::kSetLineCoding, 0, 6), Bytes(6, 0)).stalled());
  EXPECT_TRUE(dev.control(cdc_req(true, cdc::kGetLineCoding, 0, 8)).stalled());
  EXPECT_TRUE(dev.control(cdc_req(true, cdc::kGetLineCoding, 0, 7, composite::kCdcDataInterface)).stalled());
}

TEST(UsbCdc, ControlLineStateAndBreakAreRecorded) {
  UsbTestDevice dev;
  dev.enumerate();
  ASSERT_TRUE(dev.control(cdc_req(false, cdc::kSetControlLineState, 3, 0)).ok());
  EXPECT_TRUE(dev.usb->cdc().dtr());
  EXPECT_TRUE(dev.usb->cdc().rts());
  ASSERT_TRUE(dev.control(cdc_req(false, cdc::kSetControlLineState, 1, 0)).ok());
  EXPECT_TRUE(dev.usb->cdc().dtr());
  EXPECT_FALSE(dev.usb->cdc().rts());
  EXPECT_TRUE(dev.control(cdc_req(false, cdc::kSetControlLineState, 4, 0)).stalled()) << "reserved bits";
  ASSERT_TRUE(dev.control(cdc_req(false, cdc::kSendBreak, 250, 0)).ok());
  EXPECT_EQ(dev.usb->cdc().break_ms(), 250);
  EXPECT_EQ(dev.usb->cdc().breaks(), 1u);
  EXPECT_TRUE(dev.control(cdc_req(false, cdc::kSendBreak, 250, 2), Bytes(2, 0)).stalled());
  // Unsupported ACM requests (SEND_ENCAPSULATED_COMMAND 0x00, SET_COMM_FEATURE 0x02).
  EXPECT_TRUE(dev.control(cdc_req(false, 0x00, 0, 4), Bytes(4, 0)).stalled());
  EXPECT_TRUE(dev.control(cdc_req(false, 0x02, 1, 2), Bytes(2, 0)).stalled());
}

TEST(UsbCdc, ClassRequestsBeforeConfigurationStall) {
  UsbTestDevice dev;
  dev.controller.bus_reset();
  EXPECT_TRUE(dev.control(cdc_req(true, cdc::kGetLineCoding, 0, 7)).stalled());
}

// A deterministic sensor frame (physical units): each channel at its mean
// plus a phase-shifted sinusoid of one standard deviation.
firmware::SensorFrame<Q> frame_at(int t) {
  firmware::SensorFrame<Q> f;
  for (int i = 0; i < Q::kY; ++i) f.y[i] = Q::kYMean[i] + Q::kYStd[i] * static_cast<float>(std::sin(0.3 * t + i));
  for (int i = 0; i < Q::kU; ++i) f.u_prev[i] = Q::kUMean[i] + Q::kUStd[i] * static_cast<float>(std::cos(0.2 * t + i));
  return f;
}

// The requests of a session (reset, info, detect mode, 6 sensor frames,
// control mode, 3 frames), numbered by a LinkClient that sees the twin's
// replies; `expected` gets the twin's reply bytes.
Bytes session_bytes(link::DeviceLink<Q>& twin, Bytes& expected) {
  link::LinkClient<Q> client;
  link::StreamDecoder rx;
  Bytes all;
  std::uint8_t wire[link::kMaxWireFrame];
  const auto add = [&](std::size_t n) {
    all.insert(all.end(), wire, wire + n);
    for (std::size_t i = 0; i < n; ++i) {
      const auto out = twin.receive(wire[i]);
      expected.insert(expected.end(), out.begin(), out.end());
      for (const std::uint8_t b : out) {
        if (rx.push(b) == link::StreamDecoder::Event::kFrame) client.accept(rx.frame());
      }
    }
  };
  add(client.reset(wire));
  add(client.info_request(wire));
  add(client.set_mode(firmware::Mode::kDetect, wire));
  for (int t = 0; t < 6; ++t) add(client.sensor_frame(frame_at(t), wire));
  add(client.set_mode(firmware::Mode::kControl, wire));
  for (int t = 6; t < 9; ++t) add(client.sensor_frame(frame_at(t), wire));
  return all;
}

TEST(UsbCdc, LinkFramesRoundTripBitForBitThroughTheRealDispatcher) {
  UsbTestDevice dev;
  dev.enumerate();
  // The twin: the same link device end, fed directly.
  auto twin_runtime = std::make_unique<firmware::HadynetRuntime<Q>>();
  auto twin = std::make_unique<link::DeviceLink<Q>>(*twin_runtime);

  Bytes expected;
  const Bytes requests = session_bytes(*twin, expected);
  ASSERT_FALSE(expected.empty());

  Bytes received;
  std::size_t sent = 0;
  while (sent < requests.size()) {
    const std::size_t n = std::min<std::size_t>(64, requests.size() - sent);
    const Handshake h = dev.controller.out_token(0x02, std::span<const std::uint8_t>(requests).subspan(sent, n));
    if (h == Handshake::kAck) sent += n;
    ASSERT_NE(h, Handshake::kStall);
    dev.usb->service();
    std::vector<std::size_t> packets;
    const Bytes chunk = drain_in(dev.controller, 0x82, &packets);
    if (!packets.empty()) {
      EXPECT_LT(packets.back(), 64u) << "each burst ends with a short packet or a ZLP";
    }
    received.insert(received.end(), chunk.begin(), chunk.end());
  }
  for (int i = 0; i < 4; ++i) {  // flush what is still queued
    dev.usb->service();
    const Bytes chunk = drain_in(dev.controller, 0x82);
    received.insert(received.end(), chunk.begin(), chunk.end());
  }
  EXPECT_EQ(received, expected);
  EXPECT_EQ(dev.usb->cdc().dropped_reply_bytes(), 0u);

  // And the replies are what the link says: every one a success, the info
  // reply names the compiled model.
  link::StreamDecoder rx;
  int replies = 0;
  for (const std::uint8_t b : received) {
    if (rx.push(b) != link::StreamDecoder::Event::kFrame) continue;
    const link::Reply r = link::parse_reply(rx.frame());
    ASSERT_TRUE(r.status.ok());
    EXPECT_NE(r.type, link::MessageType::kError) << "reply " << replies;
    if (r.type == link::MessageType::kInfo) {
      link::InfoReply info;
      ASSERT_TRUE(link::decode_info(r.payload, info));
      EXPECT_EQ(info.model_hash, Q::kModelHash);
    }
    ++replies;
  }
  EXPECT_EQ(replies, 13) << "reset, info, 2 set-mode, 9 sensor frames";
}

TEST(UsbCdc, BackpressureNaksOutUntilRepliesDrainAndLosesNothing) {
  UsbTestDevice dev;
  dev.enumerate();
  auto twin_runtime = std::make_unique<firmware::HadynetRuntime<Q>>();
  auto twin = std::make_unique<link::DeviceLink<Q>>(*twin_runtime);
  // 5 info requests per packet (12 bytes each; the 2nd..5th get "out of
  // order" error replies: deterministic, as for the twin), 4 packets.
  link::LinkClient<Q> client;
  std::uint8_t wire[link::kMaxWireFrame];
  const std::size_t n = client.info_request(wire);
  ASSERT_EQ(n, 12u);
  Bytes packet;
  for (int k = 0; k < 5; ++k) packet.insert(packet.end(), wire, wire + n);
  Bytes expected;
  for (int p = 0; p < 4; ++p) {
    for (const std::uint8_t b : packet) {
      const auto out = twin->receive(b);
      expected.insert(expected.end(), out.begin(), out.end());
    }
  }
  // Without reading IN, the device stops consuming when its ring cannot
  // take another worst-case reply, and NAKs further OUT packets.
  int acked = 0;
  for (int p = 0; p < 4; ++p) {
    if (dev.controller.out_token(0x02, packet) == Handshake::kAck) ++acked;
    dev.usb->service();
  }
  EXPECT_LT(acked, 4) << "some OUT packet must have been NAKed";
  EXPECT_GT(dev.usb->cdc().rx_pending(), 0u);
  Bytes received;
  for (int guard = 0; guard < 50 && (acked < 4 || dev.usb->cdc().rx_pending() > 0 || dev.usb->cdc().tx_pending() > 0);
       ++guard) {
    const Bytes chunk = drain_in(dev.controller, 0x82);
    received.insert(received.end(), chunk.begin(), chunk.end());
    dev.usb->service();
    if (acked < 4 && dev.controller.out_token(0x02, packet) == Handshake::kAck) ++acked;
    dev.usb->service();
  }
  const Bytes rest = drain_in(dev.controller, 0x82);
  received.insert(received.end(), rest.begin(), rest.end());
  EXPECT_EQ(acked, 4);
  EXPECT_EQ(received, expected);
}

TEST(UsbCdc, HaltedBulkOutStallsAndResumesAfterClearFeature) {
  UsbTestDevice dev;
  dev.enumerate();
  const SetupPacket halt{request_type(false, RequestKind::kStandard, Recipient::kEndpoint), request::kSetFeature, 0,
                         0x02, 0};
  SetupPacket clear = halt;
  clear.request = request::kClearFeature;
  ASSERT_TRUE(dev.control(halt).ok());
  const Bytes one = {0x00};
  EXPECT_EQ(dev.controller.out_token(0x02, one), Handshake::kStall);
  ASSERT_TRUE(dev.control(clear).ok());
  EXPECT_EQ(dev.controller.out_token(0x02, one), Handshake::kAck) << "re-armed after CLEAR_FEATURE";
}

// An endpoint whose every byte produces exactly 64 reply bytes: the ZLP case.
struct SixtyFourByteReplies {
  std::span<const std::uint8_t> receive(std::uint8_t byte) noexcept {
    for (std::size_t i = 0; i < reply.size(); ++i) reply[i] = static_cast<std::uint8_t>(byte + i);
    return reply;
  }
  std::array<std::uint8_t, 64> reply{};
};

TEST(UsbCdc, AFullLastPacketIsFollowedByAZeroLengthPacket) {
  FakeController c;
  RecordingDetachHook hook;
  SixtyFourByteReplies endpoint;
  auto usb = std::make_unique<HadynetUsbDevice<Q, SixtyFourByteReplies, 64>>(c, endpoint, ModelSlotsAccess{}, hook,
                                                                            kTestUid, "0.1.0");
  usb->start();
  c.bus_reset();
  ASSERT_TRUE(c.control(UsbTestDevice::setup_out_device(request::kSetAddress, 1), {}, {}).ok());
  ASSERT_TRUE(c.control(UsbTestDevice::setup_out_device(request::kSetConfiguration, 1), {}, {}).ok());
  const Bytes one = {0x10};
  ASSERT_EQ(c.out_token(0x02, one), Handshake::kAck);
  usb->service();
  std::vector<std::size_t> packets;
  const Bytes got = drain_in(c, 0x82, &packets);
  EXPECT_EQ(packets, (std::vector<std::size_t>{64, 0}));
  ASSERT_EQ(got.size(), 64u);
  EXPECT_EQ(got[0], 0x10);
  EXPECT_EQ(got[63], 0x10 + 63);
}

}  // namespace
}  // namespace hadynet::usb::testing
