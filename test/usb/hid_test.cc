// HID telemetry over the interrupt IN endpoint and its class requests,
// through the host backend; reports decoded by the host decoder and compared
// with the published records bit for bit (exact, tolerance zero).
//
// The record is app::PeriodRecord, its payload the link's 0x88 period result
// (219 bytes for the hand's model: kLoadcells 9, kY 27, kU 8), so a set is 4
// reports of 64 bytes (it was 3 with the 152-byte version-1 record); the
// expectations are the old ones with that size.
#include <gtest/gtest.h>

#include <cstring>

#include "firmware/app/period_loop.h"
#include "firmware/app/period_record.h"
#include "firmware/app/synthetic_frames.h"
#include "firmware/usb/telemetry_decoder.h"
#include "period_record_bits.h"
#include "usb_test_device.h"

namespace hadynet::usb::testing {
namespace {

constexpr std::uint8_t kHid = composite::kHidInterface;
constexpr std::size_t kParts = TelemetryLayout<Q>::kParts;  // 4 for the hand's model
static_assert(kParts == 4);

app::PeriodRecord<Q> record(std::uint32_t seq) {
  app::PeriodRecord<Q> r;
  r.sequence = seq;
  r.period = seq * 2;
  r.mode = firmware::Mode::kDetect;
  r.flags = app::kRecordPredictionValid | app::kRecordStepped | app::kRecordStaleMuscleState;
  r.muscle_state_age = seq;
  r.overruns = seq / 2;
  r.missed_periods = seq;
  for (int k = 0; k < app::ChannelLayout<Q>::kLoadcells; ++k) r.loadcells_N[k] = static_cast<float>(k) - 0.75f;
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
    const app::PeriodRecord<Q> r = record(seq);
    dev.usb->publish(r);
    std::vector<std::size_t> packets;
    const Bytes bytes = drain_in(dev.controller, composite::kHidReportIn, &packets);
    ASSERT_EQ(packets, (std::vector<std::size_t>{64, 64, 64, 64}));
    TelemetryDecoder<Q>::Event e = TelemetryDecoder<Q>::Event::kNone;
    for (std::size_t p = 0; p < kParts; ++p) e = dec.push(std::span(bytes).subspan(64 * p, 64));
    ASSERT_EQ(e, TelemetryDecoder<Q>::Event::kRecord);
    EXPECT_EQ(dec.record().sequence, seq);
    expect_same_bits<Q>(dec.record(), r, static_cast<int>(seq));
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
  ASSERT_EQ(rest.size(), 3u * 64 + 4u * 64) << "the rest of set 1, then set 4";
  for (std::size_t p = 0; p < rest.size() / 64; ++p) dec.push(std::span(rest).subspan(64 * p, 64));
  EXPECT_EQ(dec.stats().records, 2u);
  EXPECT_EQ(dec.record().sequence, 4u);
  EXPECT_EQ(dec.stats().dropped, 2u) << "sequence 2 and 3";
  EXPECT_EQ(dev.usb->hid().overwritten(), 2u);
}

// A real PeriodLoop run (the link's own loop inside the test device; the
// test plays the board): each period's record, published as the firmware
// does (PeriodLoop::latest() after end_period()), comes out of the host
// decoder bit for bit, through detect and control mode, a stale muscle
// state, a period without a loadcell scan, an overrun and missed period
// boundaries. The host loses the sets of periods 6 and 7 whole and the last
// report of period 11's; the decoder counts the three from the sequence
// numbers.
TEST(UsbHid, PeriodLoopRecordsDecodeBitForBitAndLostSetsAreCounted) {
  UsbTestDevice dev;
  dev.enumerate();
  app::PeriodLoop<Q>& loop = dev.link->loop();
  app::SyntheticFrames<Q> frames(2024);
  TelemetryDecoder<Q> dec;
  constexpr std::uint32_t kTicks = 5'000'000;  // per period (25 MHz / 5 Hz)
  constexpr int kPeriods = 20;
  std::uint32_t missed = 0;
  std::uint16_t seen_flags = 0;
  for (int t = 0; t < kPeriods; ++t) {
    if (t == 12) dev.runtime->set_mode(firmware::Mode::kControl);
    firmware::SensorFrame<Q> frame;
    frames.next(frame);
    app::MuscleState<Q> muscle;
    app::PeriodLoop<Q>::LoadcellReading reading;
    reading.valid = t != 9;  // no loadcell scan in period 9
    app::split_frame<Q>(frame, muscle, reading.newtons);
    if (t != 4 && t != 5) loop.receive_muscle_state(muscle);  // 4, 5: the one of period 3, stale
    if (t == 14) missed += 2;                                 // the board missed two boundaries
    loop.run_period(reading, missed);
    loop.end_period(t == 8 ? kTicks + 1 : kTicks / 2, kTicks);  // 8: overrun
    const app::PeriodRecord<Q>& record = loop.latest();
    ASSERT_EQ(record.sequence, static_cast<std::uint32_t>(t + 1));
    seen_flags = static_cast<std::uint16_t>(seen_flags | record.flags);

    dev.usb->publish(record);
    std::vector<std::size_t> packets;
    const Bytes bytes = drain_in(dev.controller, composite::kHidReportIn, &packets);
    ASSERT_EQ(packets, (std::vector<std::size_t>(kParts, 64))) << t;
    if (t == 6 || t == 7) continue;  // the host never sees these sets
    const std::size_t parts = t == 11 ? kParts - 1 : kParts;
    TelemetryDecoder<Q>::Event e = TelemetryDecoder<Q>::Event::kNone;
    for (std::size_t p = 0; p < parts; ++p) e = dec.push(std::span(bytes).subspan(64 * p, 64));
    if (t == 11) {
      EXPECT_EQ(e, TelemetryDecoder<Q>::Event::kNone);
      continue;
    }
    ASSERT_EQ(e, TelemetryDecoder<Q>::Event::kRecord) << t;
    expect_same_bits<Q>(dec.record(), loop.latest(), t);
  }
  // The run went through what it was written for.
  for (const std::uint16_t flag : {app::kRecordPredictionValid, app::kRecordDistanceValid,
                                   app::kRecordCommandValid, app::kRecordStepped, app::kRecordStaleMuscleState,
                                   app::kRecordNoLoadcells, app::kRecordOverrun}) {
    EXPECT_NE(seen_flags & flag, 0) << "flag " << flag;
  }
  EXPECT_EQ(dec.record().mode, firmware::Mode::kControl);
  EXPECT_EQ(dec.record().period, static_cast<std::uint32_t>(kPeriods + 2));
  EXPECT_EQ(dec.record().overruns, 1u);
  const TelemetryStats& s = dec.stats();
  EXPECT_EQ(s.records, static_cast<std::uint64_t>(kPeriods - 3));
  EXPECT_EQ(s.dropped, 3u) << "sequence numbers 7, 8 (periods 6, 7) and 12 (period 11)";
  EXPECT_EQ(s.incomplete_sets, 1u) << "period 11's";
  EXPECT_EQ(s.bad_reports, 0u);
  EXPECT_EQ(s.bad_payloads, 0u);
  EXPECT_EQ(dev.usb->hid().sets_sent(), static_cast<std::uint32_t>(kPeriods));
  EXPECT_EQ(dev.usb->hid().overwritten(), 0u);
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
  ASSERT_EQ(bytes.size(), 256u) << "the pending record goes out after the halt is cleared";
  EXPECT_EQ(bytes[4], 2);
}

}  // namespace
}  // namespace hadynet::usb::testing
