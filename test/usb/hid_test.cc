// HID telemetry over the interrupt IN endpoint and its class requests,
// through the host backend; reports decoded by the host decoder and compared
// with the published records bit for bit (exact).
#include <gtest/gtest.h>

#include <cstring>

#include "firmware/usb/telemetry_decoder.h"
#include "usb_test_device.h"

namespace hadynet::usb::testing {
namespace {

constexpr std::uint8_t kHid = composite::kHidInterface;

TelemetryRecord<Q> record(std::uint32_t seq) {
  TelemetryRecord<Q> r;
  r.sequence = seq;
  r.period = seq * 2;
  r.mode = 1;
  r.flags = kTelemetryPredictionValid | kTelemetryStaleInput;
  r.d = static_cast<float>(seq) + 0.5f;
  for (int i = 0; i < Q::kY; ++i) r.prediction[i] = static_cast<float>(seq * 100 + static_cast<std::uint32_t>(i));
  for (int i = 0; i < Q::kU; ++i) r.command[i] = -static_cast<float>(i);
  return r;
}

SetupPacket hid_get_descriptor(std::uint8_t type, std::uint16_t length) {
  return {request_type(true, RequestKind::kStandard, Recipient::kInterface), request::kGetDescriptor,
          static_cast<std::uint16_t>(type << 8), kHid, length};
}

TEST(UsbHid, HidAndReportDescriptors) {
  UsbTestDevice dev;
  dev.enumerate();
  Bytes in;
  ASSERT_TRUE(dev.control(hid_get_descriptor(descriptor::kHid, 9), {}, &in).ok());
  EXPECT_EQ(in, Bytes(hid::kHidDescriptor.begin(), hid::kHidDescriptor.end()));
  ASSERT_EQ(in.size(), 9u);
  EXPECT_EQ((Bytes{in[0], in[1], in[2], in[3]}), (Bytes{9, 0x21, 0x11, 0x01})) << "HID 1.11";
  EXPECT_EQ((Bytes{in[6], in[7], in[8]}), (Bytes{0x22, 21, 0})) << "one report descriptor of 21 bytes";
  ASSERT_TRUE(dev.control(hid_get_descriptor(descriptor::kHidReport, 255), {}, &in).ok());
  ASSERT_EQ(in.size(), 21u);
  // Vendor usage page 0xFF00, 64 input bytes: checked item by item.
  EXPECT_EQ((Bytes{in[0], in[1], in[2]}), (Bytes{0x06, 0x00, 0xFF}));
  EXPECT_EQ((Bytes{in[14], in[15], in[16], in[17]}), (Bytes{0x75, 0x08, 0x95, 0x40}));
  EXPECT_EQ((Bytes{in[18], in[19], in[20]}), (Bytes{0x81, 0x02, 0xC0}));
  // Physical descriptor (0x23) and a non-zero index: STALL.
  EXPECT_TRUE(dev.control(hid_get_descriptor(0x23, 9)).stalled());
  SetupPacket s = hid_get_descriptor(descriptor::kHidReport, 255);
  s.value |= 1;
  EXPECT_TRUE(dev.control(s).stalled());
}

TEST(UsbHid, OneReportSetPerPublishedRecordDecodesExactly) {
  UsbTestDevice dev;
  dev.enumerate();
  TelemetryDecoder<Q> dec;
  for (std::uint32_t seq = 1; seq <= 4; ++seq) {
    const TelemetryRecord<Q> r = record(seq);
    dev.usb->publish(r);
    std::vector<std::size_t> packets;
    const Bytes bytes = drain_in(dev.controller, composite::kHidReportIn, &packets);
    ASSERT_EQ(packets, (std::vector<std::size_t>{64, 64, 64}));
    TelemetryDecoder<Q>::Event e = TelemetryDecoder<Q>::Event::kNone;
    for (int p = 0; p < 3; ++p) e = dec.push(std::span(bytes).subspan(64 * p, 64));
    ASSERT_EQ(e, TelemetryDecoder<Q>::Event::kRecord);
    EXPECT_EQ(dec.record().sequence, seq);
    EXPECT_EQ(std::memcmp(dec.record().prediction, r.prediction, sizeof(r.prediction)), 0);
    EXPECT_EQ(std::memcmp(dec.record().command, r.command, sizeof(r.command)), 0);
    EXPECT_EQ(dec.record().flags, r.flags);
  }
  EXPECT_EQ(dec.stats().dropped, 0u);
  EXPECT_EQ(dev.usb->hid().sets_sent(), 4u);
}

TEST(UsbHid, ASlowHostSeesTheNewestRecordAndTheGapAsDrops) {
  UsbTestDevice dev;
  dev.enumerate();
  TelemetryDecoder<Q> dec;
  std::uint8_t packet[64];
  std::size_t n = 0;
  // Set 1 starts; the host reads one report, then 3 more periods pass.
  dev.usb->publish(record(1));
  ASSERT_EQ(dev.controller.in_token(composite::kHidReportIn, packet, n), Handshake::kAck);
  dec.push(std::span<const std::uint8_t>(packet, n));
  dev.usb->publish(record(2));
  dev.usb->publish(record(3));
  dev.usb->publish(record(4));  // 2 and 3 replaced while set 1 was on its way
  const Bytes rest = drain_in(dev.controller, composite::kHidReportIn);
  ASSERT_EQ(rest.size(), 2u * 64 + 3u * 64) << "the rest of set 1, then set 4";
  for (std::size_t p = 0; p < rest.size() / 64; ++p) dec.push(std::span(rest).subspan(64 * p, 64));
  EXPECT_EQ(dec.stats().records, 2u);
  EXPECT_EQ(dec.record().sequence, 4u);
  EXPECT_EQ(dec.stats().dropped, 2u) << "sequence 2 and 3";
  EXPECT_EQ(dev.usb->hid().overwritten(), 2u);
}

TEST(UsbHid, GetReportSetIdleGetIdle) {
  UsbTestDevice dev;
  dev.enumerate();
  dev.usb->publish(record(5));
  Bytes in;
  const SetupPacket get_report = UsbTestDevice::class_interface(true, hid::kGetReport, 0x0100, kHid, 64);
  ASSERT_TRUE(dev.control(get_report, {}, &in).ok());
  ASSERT_EQ(in.size(), 64u);
  EXPECT_EQ(in[1], 0) << "part 0";
  EXPECT_EQ(in[4], 5) << "sequence of the newest record";
  // Feature (3) and output (2) reports do not exist; report ID 1 neither.
  EXPECT_TRUE(dev.control(UsbTestDevice::class_interface(true, hid::kGetReport, 0x0300, kHid, 64)).stalled());
  EXPECT_TRUE(dev.control(UsbTestDevice::class_interface(true, hid::kGetReport, 0x0101, kHid, 64)).stalled());
  ASSERT_TRUE(dev.control(UsbTestDevice::class_interface(false, hid::kSetIdle, 0x7D00, kHid, 0)).ok());
  ASSERT_TRUE(dev.control(UsbTestDevice::class_interface(true, hid::kGetIdle, 0, kHid, 1), {}, &in).ok());
  EXPECT_EQ(in, Bytes{0x7D}) << "500 ms in 4 ms units";
  EXPECT_TRUE(dev.control(UsbTestDevice::class_interface(true, hid::kGetIdle, 0, kHid, 2)).stalled());
  EXPECT_TRUE(dev.control(UsbTestDevice::class_interface(false, hid::kSetIdle, 0x0001, kHid, 0)).stalled())
      << "report ID 1 does not exist";
  // No boot protocol, no output reports.
  EXPECT_TRUE(dev.control(UsbTestDevice::class_interface(true, hid::kGetProtocol, 0, kHid, 1)).stalled());
  EXPECT_TRUE(dev.control(UsbTestDevice::class_interface(false, hid::kSetProtocol, 0, kHid, 0)).stalled());
  EXPECT_TRUE(dev.control(UsbTestDevice::class_interface(false, hid::kSetReport, 0x0200, kHid, 4), Bytes(4, 0))
                  .stalled());
}

TEST(UsbHid, NothingIsSentBeforeConfigurationOrWhileHalted) {
  UsbTestDevice dev;
  dev.controller.bus_reset();
  dev.usb->publish(record(1));
  EXPECT_FALSE(dev.controller.transfer_active(composite::kHidReportIn));
  dev.enumerate();
  const SetupPacket halt{request_type(false, RequestKind::kStandard, Recipient::kEndpoint), request::kSetFeature, 0,
                         composite::kHidReportIn, 0};
  SetupPacket clear = halt;
  clear.request = request::kClearFeature;
  ASSERT_TRUE(dev.control(halt).ok());
  dev.usb->publish(record(2));
  std::uint8_t packet[64];
  std::size_t n = 0;
  EXPECT_EQ(dev.controller.in_token(composite::kHidReportIn, packet, n), Handshake::kStall);
  ASSERT_TRUE(dev.control(clear).ok());
  const Bytes bytes = drain_in(dev.controller, composite::kHidReportIn);
  ASSERT_EQ(bytes.size(), 192u) << "the pending record goes out after the halt is cleared";
  EXPECT_EQ(bytes[4], 2);
}

}  // namespace
}  // namespace hadynet::usb::testing
