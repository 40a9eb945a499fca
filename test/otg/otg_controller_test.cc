// The OTG FS driver's register programming and interrupt handling against
// the fake core (fake_otg_fs.h). Expected register values are written out
// from RM0090's bit positions and the documented FIFO plan, not computed by
// the driver's own helpers.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <numeric>
#include <vector>

#include "boards/stm32f405/otg_fs_controller.h"
#include "test/otg/fake_otg_fs.h"

namespace hadynet::board::stm32::testing {
namespace {

using usb::ControllerEvent;
using usb::EndpointType;
using Type = ControllerEvent::Type;

struct RecordingHandler final : usb::ControllerEventHandler {
  void handle(const ControllerEvent& event) noexcept override { events.push_back(event); }
  std::vector<ControllerEvent> events;
};

std::vector<std::uint8_t> bytes_of(const std::vector<std::uint32_t>& words, std::size_t first, std::size_t count) {
  std::vector<std::uint8_t> out;
  for (std::size_t w = first; w < first + count; ++w) {
    for (int k = 0; k < 4; ++k) out.push_back(static_cast<std::uint8_t>(words[w] >> (8 * k)));
  }
  return out;
}

class OtgFsControllerTest : public ::testing::Test {
 protected:
  void SetUp() override { driver.init(handler); }

  // USB reset and enumeration at full speed, events forgotten.
  void reset_bus() {
    core.bus_reset();
    core.enumeration_done();
    driver.poll();
    handler.events.clear();
  }

  FakeOtgFs core;
  RecordingHooks hooks;
  OtgFsOptions options;
  RecordingHandler handler;
  FakeDriver driver{core, hooks, options};
};

// ---- init ---------------------------------------------------------------------------

TEST_F(OtgFsControllerTest, InitResetsTheCoreAndForcesFullSpeedDeviceMode) {
  EXPECT_EQ(hooks.enables, 1);
  EXPECT_GE(hooks.waited_ms, 25u);  // forced mode takes effect after 25 ms
  EXPECT_EQ(core.core_resets(), 1);
  EXPECT_EQ(driver.wait_timeouts(), 0u);

  const std::uint32_t gusbcfg = core.reg(otg::kGusbcfg);
  EXPECT_NE(gusbcfg & (1u << 30), 0u) << "FDMOD";
  EXPECT_EQ(gusbcfg & (1u << 29), 0u) << "FHMOD";
  EXPECT_NE(gusbcfg & (1u << 6), 0u) << "PHYSEL";
  EXPECT_EQ((gusbcfg >> 10) & 0xF, 6u) << "TRDT for a 168 MHz AHB clock";

  // Default board data: a bus-powered device, VBUS not sensed.
  EXPECT_EQ(core.reg(otg::kGccfg), (1u << 16) | (1u << 21)) << "PWRDWN | NOVBUSSENS";

  EXPECT_EQ(core.reg(otg::kDcfg) & 3u, 3u) << "DSPD full speed";
  EXPECT_EQ((core.reg(otg::kDcfg) >> 4) & 0x7F, 0u) << "DAD";
  EXPECT_NE(core.reg(otg::kDctl) & (1u << 1), 0u) << "SDIS: no pull-up until set_connected";
  EXPECT_EQ(core.reg(otg::kPcgcctl), 0u);

  EXPECT_EQ(core.reg(otg::kGahbcfg), (1u << 0) | (1u << 7)) << "GINTMSK | TXFELVL";
  const std::uint32_t wanted = (1u << 12) | (1u << 13) | (1u << 4) | (1u << 18) | (1u << 19) | (1u << 11) | (1u << 31);
  EXPECT_EQ(core.reg(otg::kGintmsk), wanted) << "USBRST ENUMDNE RXFLVL IEPINT OEPINT USBSUSP WKUPINT";
  EXPECT_EQ(core.reg(otg::kDaintmsk), (1u << 0) | (1u << 16));
  EXPECT_EQ(core.reg(otg::kDoepmsk), (1u << 0) | (1u << 3)) << "XFRC | STUP";
  EXPECT_EQ(core.reg(otg::kDiepmsk), 1u << 0) << "XFRC";
  EXPECT_EQ(core.reg(otg::doeptsiz(0)) >> 29, 3u) << "STUPCNT: 3 back-to-back SETUPs";
}

TEST(OtgFsControllerOptions, VbusSensingOnPa9SetsVbusbsen) {
  FakeOtgFs core;
  RecordingHooks hooks;
  RecordingHandler handler;
  const OtgFsOptions options{.vbus_sensing = true, .ahb_clock_hz = 168'000'000};
  FakeDriver driver(core, hooks, options);
  driver.init(handler);
  EXPECT_EQ(core.reg(otg::kGccfg), (1u << 16) | (1u << 19)) << "PWRDWN | VBUSBSEN, NOVBUSSENS clear";
}

TEST(OtgFsTurnaround, FollowsTheReferenceManualTable) {
  EXPECT_EQ(turnaround_time(168'000'000), 0x6u);
  EXPECT_EQ(turnaround_time(32'000'000), 0x6u);
  EXPECT_EQ(turnaround_time(30'000'000), 0x7u);
  EXPECT_EQ(turnaround_time(25'000'000), 0x8u);
  EXPECT_EQ(turnaround_time(16'500'000), 0xDu);
  EXPECT_EQ(turnaround_time(14'200'000), 0xFu);
  EXPECT_EQ(turnaround_time(14'000'000), 0u);
}

TEST_F(OtgFsControllerTest, FifoLayoutIsThePlannedOneAndFitsThe320WordRam) {
  // The plan (otg_fs_controller.h): RX 160, TX0 16, TX1 16, TX2 64, TX3 32 words.
  EXPECT_EQ(core.reg(otg::kGrxfsiz), 160u);
  EXPECT_EQ(core.reg(otg::kDieptxf0), (16u << 16) | 160u);
  EXPECT_EQ(core.reg(otg::dieptxf(1)), (16u << 16) | 176u);
  EXPECT_EQ(core.reg(otg::dieptxf(2)), (64u << 16) | 192u);
  EXPECT_EQ(core.reg(otg::dieptxf(3)), (32u << 16) | 256u);

  // From the registers: [start, start + depth) intervals, in order, disjoint,
  // each TX FIFO >= 16 words, all inside 320 words.
  struct Range {
    std::uint32_t start, words;
  };
  std::vector<Range> ranges = {{0, core.reg(otg::kGrxfsiz) & 0xFFFF}};
  for (int n = 0; n < 4; ++n) {
    const std::uint32_t r = core.reg(n == 0 ? otg::kDieptxf0 : otg::dieptxf(n));
    ranges.push_back({r & 0xFFFF, r >> 16});
    EXPECT_GE(r >> 16, 16u) << "TX FIFO " << n;
  }
  for (std::size_t i = 1; i < ranges.size(); ++i) {
    EXPECT_GE(ranges[i].start, ranges[i - 1].start + ranges[i - 1].words) << "overlap at FIFO " << i;
  }
  EXPECT_LE(ranges.back().start + ranges.back().words, 320u);
}

// ---- seam calls ------------------------------------------------------------------------

TEST_F(OtgFsControllerTest, SetConnectedDrivesSoftDisconnect) {
  driver.set_connected(true);
  EXPECT_EQ(core.reg(otg::kDctl) & (1u << 1), 0u);
  driver.set_connected(false);
  EXPECT_NE(core.reg(otg::kDctl) & (1u << 1), 0u);
}

TEST_F(OtgFsControllerTest, SetAddressWritesDadAtOnceAndKeepsTheSpeed) {
  reset_bus();
  driver.set_address(0x5A);
  EXPECT_EQ((core.reg(otg::kDcfg) >> 4) & 0x7F, 0x5Au);
  EXPECT_EQ(core.reg(otg::kDcfg) & 3u, 3u);
  driver.set_address(3);
  EXPECT_EQ((core.reg(otg::kDcfg) >> 4) & 0x7F, 3u);
}

TEST_F(OtgFsControllerTest, OpenEndpointProgramsControlFields) {
  reset_bus();
  core.clear_data0_marks();
  ASSERT_TRUE(driver.open_endpoint({0x82, EndpointType::kBulk, 64}));
  // USBAEP(15) | EPTYP bulk (2 << 18) | MPSIZ 64 | TXFNUM 2 (<< 22); SNAK leaves NAKSTS.
  EXPECT_EQ(core.reg(otg::diepctl(2)) & ~(1u << 17), (1u << 15) | (2u << 18) | 64u | (2u << 22));
  EXPECT_TRUE(core.data0_set(true, 2)) << "SD0PID";
  ASSERT_TRUE(driver.open_endpoint({0x02, EndpointType::kBulk, 64}));
  EXPECT_EQ(core.reg(otg::doepctl(2)) & ~(1u << 17), (1u << 15) | (2u << 18) | 64u);
  EXPECT_TRUE(core.data0_set(false, 2));
  ASSERT_TRUE(driver.open_endpoint({0x81, EndpointType::kInterrupt, 16}));
  EXPECT_EQ(core.reg(otg::diepctl(1)) & ~(1u << 17), (1u << 15) | (3u << 18) | 16u | (1u << 22));
  ASSERT_TRUE(driver.open_endpoint({0x83, EndpointType::kInterrupt, 64}));
  EXPECT_EQ(core.reg(otg::diepctl(3)) & ~(1u << 17), (1u << 15) | (3u << 18) | 64u | (3u << 22));
  EXPECT_EQ(core.reg(otg::kDaintmsk), (1u << 0) | (1u << 1) | (1u << 2) | (1u << 3) | (1u << 16) | (1u << 18));

  EXPECT_FALSE(driver.open_endpoint({0x80, EndpointType::kBulk, 64})) << "EP0";
  EXPECT_FALSE(driver.open_endpoint({0x84, EndpointType::kBulk, 64})) << "no EP4";
  EXPECT_FALSE(driver.open_endpoint({0x01, EndpointType::kIsochronous, 64}));
  EXPECT_FALSE(driver.open_endpoint({0x01, EndpointType::kBulk, 65}));
  EXPECT_FALSE(driver.open_endpoint({0x01, EndpointType::kBulk, 0}));
}

TEST_F(OtgFsControllerTest, CloseEndpointDeactivatesIt) {
  reset_bus();
  ASSERT_TRUE(driver.open_endpoint({0x82, EndpointType::kBulk, 64}));
  std::array<std::uint8_t, 64> data{};
  ASSERT_TRUE(driver.start_transfer(0x82, data));
  driver.close_endpoint(0x82);
  EXPECT_EQ(core.reg(otg::diepctl(2)) & ((1u << 15) | (1u << 31)), 0u) << "USBAEP and EPENA off";
  EXPECT_EQ(core.reg(otg::kDaintmsk) & (1u << 2), 0u);
  EXPECT_FALSE(driver.start_transfer(0x82, data));
  driver.poll();
  EXPECT_TRUE(handler.events.empty()) << "cancelled silently";
}

TEST_F(OtgFsControllerTest, StartTransferProgramsSizesAndEnables) {
  reset_bus();
  ASSERT_TRUE(driver.open_endpoint({0x82, EndpointType::kBulk, 64}));
  ASSERT_TRUE(driver.open_endpoint({0x02, EndpointType::kBulk, 64}));
  std::array<std::uint8_t, 128> in_data{};
  std::array<std::uint8_t, 128> out_buffer{};

  ASSERT_TRUE(driver.start_transfer(0x82, std::span<std::uint8_t>(in_data.data(), 100)));
  EXPECT_EQ(core.reg(otg::dieptsiz(2)), (2u << 19) | 100u) << "PKTCNT 2, XFRSIZ 100";
  EXPECT_NE(core.reg(otg::diepctl(2)) & (1u << 31), 0u) << "EPENA";
  EXPECT_EQ(core.reg(otg::diepctl(2)) & (1u << 17), 0u) << "CNAK cleared NAKSTS";
  EXPECT_NE(core.reg(otg::kDiepempmsk) & (1u << 2), 0u) << "TXFE of EP2 unmasked";
  EXPECT_FALSE(driver.start_transfer(0x82, in_data)) << "busy";

  ASSERT_TRUE(driver.start_transfer(0x02, out_buffer));
  EXPECT_EQ(core.reg(otg::doeptsiz(2)), (2u << 19) | 128u);
  EXPECT_NE(core.reg(otg::doepctl(2)) & (1u << 31), 0u);
  EXPECT_EQ(core.reg(otg::doepctl(2)) & (1u << 17), 0u);

  ASSERT_TRUE(driver.start_transfer(0x00, std::span<std::uint8_t>(out_buffer.data(), 64)));
  EXPECT_EQ(core.reg(otg::doeptsiz(0)), (3u << 29) | (1u << 19) | 64u) << "STUPCNT 3, one packet";
  ASSERT_TRUE(driver.start_transfer(0x80, {}));
  EXPECT_EQ(core.reg(otg::dieptsiz(0)), 1u << 19) << "a zero-length packet";
  EXPECT_EQ(core.reg(otg::kDiepempmsk) & 1u, 0u) << "nothing to push";

  EXPECT_FALSE(driver.start_transfer(0x81, in_data)) << "not open";
  ASSERT_TRUE(driver.open_endpoint({0x01, EndpointType::kBulk, 64}));
  EXPECT_FALSE(driver.start_transfer(0x01, std::span<std::uint8_t>(out_buffer.data(), 100)))
      << "OUT size not a multiple of the max packet";
}

// ---- events ---------------------------------------------------------------------------

TEST_F(OtgFsControllerTest, ScriptedSetupGivesExactlyOneSetupEvent) {
  reset_bus();
  // GET_DESCRIPTOR(device), wLength 64, as RX FIFO entries: SETUP data
  // (8 bytes, 2 words little-endian), then "SETUP stage done".
  const std::uint32_t words[2] = {0x01000680, 0x00400000};
  core.queue_rx(FakeOtgFs::rx_status(0, 6, 8), words);
  core.queue_rx(FakeOtgFs::rx_status(0, 4, 0));
  driver.poll();
  ASSERT_EQ(handler.events.size(), 1u);
  EXPECT_EQ(handler.events[0].type, Type::kSetup);
  const std::array<std::uint8_t, 8> expected = {0x80, 0x06, 0x00, 0x01, 0x00, 0x00, 0x40, 0x00};
  EXPECT_EQ(handler.events[0].setup, expected);
  EXPECT_EQ(core.rx_entries_left(), 0u);
  EXPECT_EQ(core.rx_words_left(), 0u);
  EXPECT_EQ(core.fifo_underruns(), 0);
  driver.poll();
  EXPECT_EQ(handler.events.size(), 1u) << "nothing more";
}

TEST_F(OtgFsControllerTest, BackToBackSetupsDeliverTheLastOne) {
  reset_bus();
  const std::uint32_t first[2] = {0x11111111, 0x22222222};
  const std::uint32_t last[2] = {0x00050500, 0x00000000};  // SET_ADDRESS(5)
  core.queue_rx(FakeOtgFs::rx_status(0, 6, 8), first);
  core.queue_rx(FakeOtgFs::rx_status(0, 6, 8), last);
  core.queue_rx(FakeOtgFs::rx_status(0, 4, 0));
  driver.poll();
  ASSERT_EQ(handler.events.size(), 1u);
  const std::array<std::uint8_t, 8> expected = {0x00, 0x05, 0x05, 0x00, 0x00, 0x00, 0x00, 0x00};
  EXPECT_EQ(handler.events[0].setup, expected);
}

TEST_F(OtgFsControllerTest, InTransferOf100BytesPushes16Then9WordsAndCompletes) {
  reset_bus();
  // EP1's TX FIFO holds 16 words: one 64-byte packet at a time.
  ASSERT_TRUE(driver.open_endpoint({0x81, EndpointType::kInterrupt, 64}));
  std::array<std::uint8_t, 100> data{};
  std::iota(data.begin(), data.end(), std::uint8_t{1});
  ASSERT_TRUE(driver.start_transfer(0x81, data));

  driver.poll();  // TXFE: the first packet
  ASSERT_EQ(core.pushed_words(1).size(), 16u);
  EXPECT_TRUE(handler.events.empty());
  const auto first = core.in_token(1);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->size(), 64u);

  driver.poll();  // TXFE again: the 36-byte rest
  ASSERT_EQ(core.pushed_words(1).size(), 25u);
  EXPECT_TRUE(handler.events.empty()) << "not complete before the host took the last packet";
  const auto second = core.in_token(1);
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(second->size(), 36u);

  driver.poll();  // XFRC
  ASSERT_EQ(handler.events.size(), 1u);
  EXPECT_EQ(handler.events[0].type, Type::kTransferComplete);
  EXPECT_EQ(handler.events[0].endpoint, 0x81);
  EXPECT_EQ(handler.events[0].bytes, 100);

  std::vector<std::uint8_t> sent = *first;
  sent.insert(sent.end(), second->begin(), second->end());
  EXPECT_EQ(sent, std::vector<std::uint8_t>(data.begin(), data.end()));
  EXPECT_EQ(bytes_of(core.pushed_words(1), 0, 25), std::vector<std::uint8_t>(data.begin(), data.end()));
  EXPECT_EQ(core.fifo_overruns(), 0);
  EXPECT_EQ(core.reg(otg::kDiepempmsk) & (1u << 1), 0u);
}

TEST_F(OtgFsControllerTest, DeepTxFifoTakesBothPacketsAtOnceAndPadsTheLastWord) {
  reset_bus();
  ASSERT_TRUE(driver.open_endpoint({0x82, EndpointType::kBulk, 64}));  // 64-word FIFO
  std::array<std::uint8_t, 101> data{};
  std::iota(data.begin(), data.end(), std::uint8_t{7});
  ASSERT_TRUE(driver.start_transfer(0x82, data));
  driver.poll();
  ASSERT_EQ(core.pushed_words(2).size(), 16u + 10u);
  EXPECT_EQ(core.pushed_words(2).back(), static_cast<std::uint32_t>(data[100])) << "3 padding bytes of zero";
  ASSERT_TRUE(core.in_token(2).has_value());
  ASSERT_EQ(core.in_token(2)->size(), 37u);
  driver.poll();
  ASSERT_EQ(handler.events.size(), 1u);
  EXPECT_EQ(handler.events[0].bytes, 101);
}

TEST_F(OtgFsControllerTest, OutTransferEndsOnAShortPacket) {
  reset_bus();
  ASSERT_TRUE(driver.open_endpoint({0x02, EndpointType::kBulk, 64}));
  std::array<std::uint8_t, 128> buffer{};
  ASSERT_TRUE(driver.start_transfer(0x02, buffer));
  std::vector<std::uint8_t> full(64), tail(10);
  std::iota(full.begin(), full.end(), std::uint8_t{0});
  std::iota(tail.begin(), tail.end(), std::uint8_t{200});
  ASSERT_TRUE(core.out_packet(2, full));
  driver.poll();
  EXPECT_TRUE(handler.events.empty());
  ASSERT_TRUE(core.out_packet(2, tail));
  driver.poll();
  ASSERT_EQ(handler.events.size(), 1u);
  EXPECT_EQ(handler.events[0].type, Type::kTransferComplete);
  EXPECT_EQ(handler.events[0].endpoint, 0x02);
  EXPECT_EQ(handler.events[0].bytes, 74);
  EXPECT_TRUE(std::equal(full.begin(), full.end(), buffer.begin()));
  EXPECT_TRUE(std::equal(tail.begin(), tail.end(), buffer.begin() + 64));
  EXPECT_EQ(core.rx_words_left(), 0u);
}

TEST_F(OtgFsControllerTest, BusResetReportsAndClearsAddressAndEndpoints) {
  reset_bus();
  driver.set_address(9);
  ASSERT_TRUE(driver.open_endpoint({0x82, EndpointType::kBulk, 64}));
  std::array<std::uint8_t, 64> data{};
  ASSERT_TRUE(driver.start_transfer(0x82, data));
  const int flushes = core.tx_flushes();

  core.bus_reset();
  driver.poll();
  ASSERT_EQ(handler.events.size(), 1u);
  EXPECT_EQ(handler.events[0].type, Type::kBusReset);
  EXPECT_EQ((core.reg(otg::kDcfg) >> 4) & 0x7F, 0u) << "DAD cleared";
  EXPECT_EQ(core.reg(otg::diepctl(2)) & ((1u << 15) | (1u << 31)), 0u);
  EXPECT_EQ(core.reg(otg::kDaintmsk), (1u << 0) | (1u << 16));
  EXPECT_GT(core.tx_flushes(), flushes);
  EXPECT_EQ(core.reg(otg::doeptsiz(0)) >> 29, 3u);
  EXPECT_FALSE(driver.start_transfer(0x82, data)) << "closed by the reset";
  EXPECT_TRUE(driver.start_transfer(0x80, {})) << "EP0 open after a reset";
}

TEST_F(OtgFsControllerTest, StallControlStallsBothDirectionsUntilTheNextSetup) {
  reset_bus();
  driver.stall_control();
  EXPECT_NE(core.reg(otg::diepctl(0)) & (1u << 21), 0u);
  EXPECT_NE(core.reg(otg::doepctl(0)) & (1u << 21), 0u);

  const std::array<std::uint8_t, 8> get_status = {0x80, 0x00, 0, 0, 0, 0, 2, 0};
  core.setup(get_status);
  driver.poll();
  ASSERT_EQ(handler.events.size(), 1u);
  EXPECT_EQ(handler.events[0].type, Type::kSetup);
  EXPECT_EQ(core.reg(otg::diepctl(0)) & (1u << 21), 0u);
  EXPECT_EQ(core.reg(otg::doepctl(0)) & (1u << 21), 0u);
}

TEST_F(OtgFsControllerTest, SetupCancelsAnActiveEp0TransferSilently) {
  reset_bus();
  std::array<std::uint8_t, 64> data{};
  ASSERT_TRUE(driver.start_transfer(0x80, data));
  driver.poll();  // pushed, waiting for the host
  const std::array<std::uint8_t, 8> setup = {0x80, 0x06, 0, 1, 0, 0, 18, 0};
  core.setup(setup);
  driver.poll();
  ASSERT_EQ(handler.events.size(), 1u);
  EXPECT_EQ(handler.events[0].type, Type::kSetup);
  EXPECT_EQ(core.reg(otg::diepctl(0)) & (1u << 31), 0u) << "EP0 IN disabled";
  EXPECT_EQ(core.queued_words(0), 0u) << "its FIFO flushed";
  EXPECT_TRUE(driver.start_transfer(0x80, data)) << "EP0 IN free again";
}

TEST_F(OtgFsControllerTest, EndpointHaltSetsAndClearsStallWithData0) {
  reset_bus();
  ASSERT_TRUE(driver.open_endpoint({0x82, EndpointType::kBulk, 64}));
  std::array<std::uint8_t, 64> data{};
  ASSERT_TRUE(driver.start_transfer(0x82, data));
  driver.set_endpoint_halt(0x82, true);
  EXPECT_NE(core.reg(otg::diepctl(2)) & (1u << 21), 0u) << "STALL";
  EXPECT_EQ(core.reg(otg::diepctl(2)) & (1u << 31), 0u) << "the transfer dropped";
  EXPECT_FALSE(driver.start_transfer(0x82, data)) << "halted";
  EXPECT_FALSE(core.in_token(2).has_value());

  core.clear_data0_marks();
  driver.set_endpoint_halt(0x82, false);
  EXPECT_EQ(core.reg(otg::diepctl(2)) & (1u << 21), 0u);
  EXPECT_TRUE(core.data0_set(true, 2)) << "SD0PID on clear";
  EXPECT_NE(core.reg(otg::diepctl(2)) & (1u << 15), 0u) << "still active";
  EXPECT_TRUE(driver.start_transfer(0x82, data));

  ASSERT_TRUE(driver.open_endpoint({0x02, EndpointType::kBulk, 64}));
  driver.set_endpoint_halt(0x02, true);
  EXPECT_NE(core.reg(otg::doepctl(2)) & (1u << 21), 0u);
  driver.poll();
  EXPECT_TRUE(handler.events.empty());
  EXPECT_EQ(driver.wait_timeouts(), 0u);
}

TEST_F(OtgFsControllerTest, SuspendAndWakeupBecomeEvents) {
  reset_bus();
  core.suspend();
  driver.poll();
  core.wakeup();
  driver.poll();
  ASSERT_EQ(handler.events.size(), 2u);
  EXPECT_EQ(handler.events[0].type, Type::kSuspend);
  EXPECT_EQ(handler.events[1].type, Type::kResume);
  driver.poll();
  EXPECT_EQ(handler.events.size(), 2u) << "latched flags were cleared";
}

TEST_F(OtgFsControllerTest, OutDataWithoutATransferIsPoppedAndCounted) {
  reset_bus();
  // A data packet for EP2 OUT that nobody armed (a misbehaving host, or a
  // transfer dropped by a halt): its words must still leave the RX FIFO.
  const std::uint32_t words[3] = {1, 2, 3};
  core.queue_rx(FakeOtgFs::rx_status(2, 2, 10), words);
  driver.poll();
  EXPECT_EQ(core.rx_words_left(), 0u);
  EXPECT_EQ(driver.dropped_out_bytes(), 10u);
  EXPECT_TRUE(handler.events.empty());
}

// A core whose soft reset never finishes (no clock, wrong pins): init()
// still returns, after bounded waits, and says so.
struct StuckResetCore : FakeOtgFs {
  std::uint32_t read(std::uint32_t offset) {
    if (offset == otg::kGrstctl) return otg::kGrstctlCoreReset;  // CSRST never clears, AHB never idle
    return FakeOtgFs::read(offset);
  }
};

TEST(OtgFsControllerStuckCore, InitReturnsAndCountsTheTimeouts) {
  StuckResetCore core;
  RecordingHooks hooks;
  RecordingHandler handler;
  OtgFsController<StuckResetCore> driver(core, hooks, OtgFsOptions{});
  driver.init(handler);
  EXPECT_GE(driver.wait_timeouts(), 3u);
}

TEST(OtgFsControllerBeforeInit, PollDoesNothing) {
  FakeOtgFs core;
  RecordingHooks hooks;
  FakeDriver driver(core, hooks, OtgFsOptions{});
  core.bus_reset();
  driver.poll();
  EXPECT_EQ(hooks.enables, 0);
}

}  // namespace
}  // namespace hadynet::board::stm32::testing
