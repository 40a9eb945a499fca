// `hadynet devices` (this build's executable) as a child process against
// the testbed: the hand listed from what it answers over EP0, the "none
// found" wording and exit code, and EP0 faults while it reads the strings.
// Expected text from cli/devices_command.cc's documented output and
// docs/usb.md; exact where the output is fixed, substring otherwise.
#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "test/usb_host/child_process.h"
#include "test/usb_host/hand_device.h"
#include "test/usb_host/test_records.h"
#include "test/usb_host/usb_testbed.h"

namespace hadynet::usb::host_testing {
namespace {

using namespace std::chrono_literals;

// Tolerance: `hadynet devices` needs ~0.1 s here; 10 s only catches a hang
// (an EP0 time-out below costs libusb's 1 s string-read time-out).
constexpr auto kChildTimeout = 10s;

std::string model_hash_text() {
  char h[17];
  std::snprintf(h, sizeof h, "%016llx", static_cast<unsigned long long>(Q::kModelHash));
  return h;
}

std::size_t lines(const std::string& s) {
  std::size_t n = 0;
  for (const char c : s) n += c == '\n';
  return n;
}

class CliDevices : public ::testing::Test {
 protected:
  void SetUp() override {
    bus_ = std::make_unique<UsbTestbed>();
    ASSERT_TRUE(bus_->ok()) << bus_->error();
  }
  void plug_hand() {
    hand_ = std::make_shared<HandDevice>();
    ASSERT_TRUE(bus_->plug(kHandDevnum, hand_)) << bus_->error();
  }
  ChildResult devices() { return run_child(*bus_, {HADYNET_CLI_EXECUTABLE, "devices"}, kChildTimeout); }

  std::unique_ptr<UsbTestbed> bus_;
  std::shared_ptr<HandDevice> hand_;
};

TEST_F(CliDevices, ListsTheHandWithSerialVersionRunningModelAndInterfaces) {
  plug_hand();
  const ChildResult r = devices();
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  EXPECT_EQ(lines(r.out), 1u) << r.out;
  EXPECT_EQ(r.out.rfind("hand ", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("bus 001 device 002"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1209:0001"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(std::string("  serial ") + kFixtureSerial + "  "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(std::string("  firmware ") + kFixtureFirmwareVersion + "  "), std::string::npos) << r.out;
  // The running model: no image in the slots, so the compiled-in one.
  EXPECT_NE(r.out.find("  model " + model_hash_text() + " (factory)  "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  interfaces link(cdc-acm),telemetry(hid),dfu-runtime,dfu-model\n"), std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find('['), std::string::npos) << "no read error expected: " << r.out;
}

TEST_F(CliDevices, NoDeviceSaysSoAndExitsOne) {
  const ChildResult r = devices();
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 1) << r.describe();
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("hadynet devices: no HADYNET device (1209:0001) and no STM32 bootloader (0483:df11) on USB"),
            std::string::npos)
      << r.err;
}

TEST_F(CliDevices, HandThatLeftIsNotListed) {
  plug_hand();
  bus_->unplug(kHandDevnum);
  const ChildResult r = devices();
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 1) << r.describe();
}

// EP0 faults on the first string read (LANGID table, before the serial):
// the hand is listed without an invented serial, the failure in brackets.
// (Exit 0 is the documented meaning "a device was listed".)
void expect_serial_unread(const ChildResult& r, const char* reason) {
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_NE(r.out.find("  serial ?  "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(std::string("[string descriptor 3: ") + reason + "]"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(kFixtureSerial), std::string::npos) << r.out;
}

TEST_F(CliDevices, StalledStringReadIsReportedNotInvented) {
  plug_hand();
  bus_->fail_next_transfer(kHandDevnum, 0x00, EPIPE);
  expect_serial_unread(devices(), "Pipe error");
}

TEST_F(CliDevices, ShortStringDescriptorIsReportedNotInvented) {
  plug_hand();
  bus_->short_next_in(kHandDevnum, 0x00, 2);  // the LANGID table cut to its 2-byte header
  expect_serial_unread(devices(), "Input/Output Error");
}

TEST_F(CliDevices, TimedOutStringReadEndsInBoundedTime) {
  plug_hand();
  bus_->hang_next_transfer(kHandDevnum, 0x00);
  const ChildResult r = devices();
  expect_serial_unread(r, "Operation timed out");
  // libusb's string read times out after 1 s (libusb_get_string_descriptor);
  // 5 s allows a loaded machine.
  EXPECT_LT(r.elapsed_s, 5.0);
}

}  // namespace
}  // namespace hadynet::usb::host_testing
