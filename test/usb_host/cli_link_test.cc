// `hadynet link --device /dev/ttyACM0` (this build's executable) against
// the hand's CDC-ACM function: the testbed plays the kernel's cdc-acm
// driver (a pty bridged to bulk 0x02/0x82, cdc_tty_bridge.h), so link frames
// go through the firmware's CDC function and link::DeviceLink and back.
#include <gtest/gtest.h>

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

// Tolerance: a round trip takes milliseconds here; the link's own connect
// time-out is 10 s, so 20 s only catches a hang.
constexpr auto kChildTimeout = 20s;

class CliLink : public ::testing::Test {
 protected:
  void SetUp() override {
    bus_ = std::make_unique<UsbTestbed>();
    ASSERT_TRUE(bus_->ok()) << bus_->error();
    hand_ = std::make_shared<HandDevice>();
    ASSERT_TRUE(bus_->plug(kHandDevnum, hand_)) << bus_->error();
    tty_ = bus_->attach_cdc_tty(kHandDevnum, "ttyACM0", 0x02, 0x82);
    ASSERT_EQ(tty_, "/dev/ttyACM0") << bus_->error();
  }
  ChildResult link(const std::vector<std::string>& action, const std::function<void()>& tick = {}) {
    std::vector<std::string> argv = {HADYNET_CLI_EXECUTABLE, "link", "--device", tty_};
    argv.insert(argv.end(), action.begin(), action.end());
    return run_child(*bus_, argv, kChildTimeout, tick);
  }

  std::unique_ptr<UsbTestbed> bus_;
  std::shared_ptr<HandDevice> hand_;
  std::string tty_;
};

TEST_F(CliLink, InfoRoundTripsThroughTheCdcFunction) {
  const ChildResult r = link({"info"});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  ASSERT_EQ(r.exit_code, 0) << r.describe();
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(Q::kModelHash));
  EXPECT_NE(r.out.find(std::string("/dev/ttyACM0: protocol ")), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(std::string("model hash ") + hash), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dims: x " + std::to_string(Q::kX) + ", u " + std::to_string(Q::kU) + ", y " +
                       std::to_string(Q::kY)),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("(the same)"), std::string::npos) << r.out;
  EXPECT_GT(bus_->packets(kHandDevnum).of(0x02), 0u) << "the frames went over bulk OUT";
  EXPECT_GT(bus_->packets(kHandDevnum).of(0x82), 0u) << "the replies came over bulk IN";
}

TEST_F(CliLink, ModeRequestIsAcknowledged) {
  const ChildResult r = link({"mode", "detect"});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  EXPECT_EQ(r.out, "/dev/ttyACM0: mode detect\n");
}

// The hand leaves while link waits for a reply: the tty hangs up and link
// ends with an error, well before its own 10 s time-out, never "ok".
TEST_F(CliLink, UnplugMidExchangeEndsWithAnError) {
  bool unplugged = false;
  const ChildResult r = link({"info"}, [&] {
    if (!unplugged && bus_->packets(kHandDevnum).of(0x02) > 0) {
      bus_->unplug(kHandDevnum);
      unplugged = true;
    }
  });
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_TRUE(unplugged);
  EXPECT_EQ(r.exit_code, 1) << r.describe();
  EXPECT_NE(r.err.find("hadynet link: "), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("model hash"), std::string::npos) << r.out;
  // Tolerance: the hang-up is seen at the next read (ms); 5 s is half the
  // link's own time-out, so a pass proves the hang-up ended it.
  EXPECT_LT(r.elapsed_s, 5.0);
}

}  // namespace
}  // namespace hadynet::usb::host_testing
