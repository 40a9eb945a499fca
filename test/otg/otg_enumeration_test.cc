// The real portable stack (hadynet::usb::UsbDevice) over the OTG FS driver
// and the fake core: bus reset, GET_DESCRIPTOR(device) whose 18 bytes must
// land in the EP0 TX FIFO, its status stage, SET_ADDRESS with DCFG.DAD
// written before the status stage, and a request on the new address.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "boards/stm32f405/otg_fs_controller.h"
#include "firmware/usb/usb_device.h"
#include "test/otg/fake_otg_fs.h"

namespace hadynet::board::stm32::testing {
namespace {

constexpr std::array<std::uint8_t, 18> kDeviceDescriptor = {18,   1,    0x00, 0x02, 0xEF, 0x02, 0x01, 64, 0x83,
                                                            0x04, 0x40, 0x57, 0x00, 0x01, 1,    2,    3,  1};
// One configuration with one interface and no endpoints (9 + 9 bytes).
constexpr std::array<std::uint8_t, 18> kConfiguration = {9, 2, 18, 0, 1, 1, 0, 0x80, 50, 9, 4, 0, 0, 0, 0xFF, 0, 0, 0};
constexpr std::array<const char*, 4> kStrings = {nullptr, "HADYNET", "test", "0001"};

std::array<std::uint8_t, 8> setup_bytes(std::uint8_t type, std::uint8_t request, std::uint16_t value,
                                        std::uint16_t length) {
  return {type, request, static_cast<std::uint8_t>(value),  static_cast<std::uint8_t>(value >> 8),
          0,    0,       static_cast<std::uint8_t>(length), static_cast<std::uint8_t>(length >> 8)};
}

class OtgFsEnumerationTest : public ::testing::Test {
 protected:
  OtgFsEnumerationTest()
      : device(driver, usb::DescriptorSet{kDeviceDescriptor, kConfiguration, kStrings},
               std::span<usb::UsbFunction* const>(), /*self_powered=*/false) {}

  FakeOtgFs core;
  RecordingHooks hooks;
  FakeDriver driver{core, hooks, OtgFsOptions{}};
  usb::UsbDevice device;
};

TEST_F(OtgFsEnumerationTest, GetDeviceDescriptorLandsInTheEp0TxFifoThenSetAddress) {
  device.start();  // init + pull-up on
  EXPECT_EQ(core.reg(otg::kDctl) & otg::kDctlSoftDisconnect, 0u);

  core.bus_reset();
  core.enumeration_done();
  driver.poll();
  EXPECT_EQ(device.state(), usb::DeviceState::kDefault);

  // GET_DESCRIPTOR(device), wLength 64 (the host's first request).
  core.setup(setup_bytes(0x80, usb::request::kGetDescriptor, 0x0100, 64));
  driver.poll();
  EXPECT_EQ(device.control_stage(), usb::ControlStage::kDataIn);
  const std::vector<std::uint32_t>& words = core.pushed_words(0);
  ASSERT_EQ(words.size(), 5u) << "18 bytes = 4 words + 2 bytes padded";
  std::vector<std::uint8_t> pushed;
  for (const std::uint32_t w : words) {
    for (int k = 0; k < 4; ++k) pushed.push_back(static_cast<std::uint8_t>(w >> (8 * k)));
  }
  EXPECT_TRUE(std::equal(kDeviceDescriptor.begin(), kDeviceDescriptor.end(), pushed.begin()));
  EXPECT_EQ(pushed[18], 0);
  EXPECT_EQ(pushed[19], 0);
  EXPECT_EQ(core.reg(otg::dieptsiz(0)), (1u << 19) | 18u);

  // The host reads it (one 18-byte packet), then the OUT status stage.
  const auto data = core.in_token(0);
  ASSERT_TRUE(data.has_value());
  EXPECT_EQ(*data, std::vector<std::uint8_t>(kDeviceDescriptor.begin(), kDeviceDescriptor.end()));
  driver.poll();
  EXPECT_EQ(device.control_stage(), usb::ControlStage::kStatusOut);
  ASSERT_TRUE(core.out_packet(0, {}));
  driver.poll();
  EXPECT_EQ(device.control_stage(), usb::ControlStage::kIdle);

  // SET_ADDRESS(7): DAD at once, the status stage (ZLP IN) still answered.
  core.bus_reset();  // hosts reset again after the first descriptor
  driver.poll();
  core.setup(setup_bytes(0x00, usb::request::kSetAddress, 7, 0));
  driver.poll();
  EXPECT_EQ((core.reg(otg::kDcfg) >> 4) & 0x7F, 7u) << "DAD before the status stage";
  EXPECT_EQ(device.control_stage(), usb::ControlStage::kStatusIn);
  const auto status = core.in_token(0);
  ASSERT_TRUE(status.has_value());
  EXPECT_TRUE(status->empty());
  driver.poll();
  EXPECT_EQ(device.state(), usb::DeviceState::kAddressed);
  EXPECT_EQ(device.address(), 7);

  // GET_DESCRIPTOR(configuration) on the new address: 18 bytes.
  core.setup(setup_bytes(0x80, usb::request::kGetDescriptor, 0x0200, 255));
  driver.poll();
  const auto config = core.in_token(0);
  ASSERT_TRUE(config.has_value());
  EXPECT_EQ(*config, std::vector<std::uint8_t>(kConfiguration.begin(), kConfiguration.end()));
  driver.poll();
  ASSERT_TRUE(core.out_packet(0, {}));
  driver.poll();
  EXPECT_EQ(device.control_stage(), usb::ControlStage::kIdle);

  EXPECT_EQ(driver.wait_timeouts(), 0u);
  EXPECT_EQ(core.fifo_underruns(), 0);
  EXPECT_EQ(core.fifo_overruns(), 0);
}

TEST_F(OtgFsEnumerationTest, UnknownRequestStallsEp0UntilTheNextSetup) {
  device.start();
  core.bus_reset();
  driver.poll();
  core.setup(setup_bytes(0x80, usb::request::kGetDescriptor, 0x0600, 10));  // device qualifier: STALL
  driver.poll();
  EXPECT_EQ(device.control_stage(), usb::ControlStage::kStalled);
  EXPECT_NE(core.reg(otg::diepctl(0)) & otg::kEpctlStall, 0u);
  EXPECT_NE(core.reg(otg::doepctl(0)) & otg::kEpctlStall, 0u);
  EXPECT_FALSE(core.in_token(0).has_value());

  core.setup(setup_bytes(0x80, usb::request::kGetDescriptor, 0x0100, 18));
  driver.poll();
  const auto data = core.in_token(0);
  ASSERT_TRUE(data.has_value());
  EXPECT_EQ(data->size(), 18u);
}

}  // namespace
}  // namespace hadynet::board::stm32::testing
