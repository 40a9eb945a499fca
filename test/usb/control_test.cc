// The EP0 control state machine and the standard requests (USB 2.0 ch. 9)
// through the host backend: scripted SETUP packets and IN/OUT tokens, exact
// expectations (handshakes, bytes, device state, calls into the seam).
#include <gtest/gtest.h>

#include "firmware/usb/composite_descriptors.h"
#include "usb_test_device.h"

namespace hadynet::usb::testing {
namespace {

using Kind = host::ControllerCall::Kind;

SetupPacket std_req(bool in, Recipient r, std::uint8_t request, std::uint16_t value, std::uint16_t index,
                    std::uint16_t length) {
  return {request_type(in, RequestKind::kStandard, r), request, value, index, length};
}

TEST(UsbControl, SetAddressTakesEffectAfterTheStatusStage) {
  UsbTestDevice dev;
  FakeController& c = dev.controller;
  EXPECT_TRUE(c.connected()) << "start() connects";
  c.bus_reset();
  c.setup(std_req(false, Recipient::kDevice, request::kSetAddress, 42, 0, 0));
  // The seam's contract: set_address() before the status stage is started.
  ASSERT_GE(c.logged(), 2u);
  EXPECT_EQ(c.call(c.logged() - 2).kind, Kind::kSetAddress);
  EXPECT_EQ(c.call(c.logged() - 2).value, 42u);
  EXPECT_EQ(c.call(c.logged() - 1).kind, Kind::kStartTransfer);
  EXPECT_EQ(c.call(c.logged() - 1).endpoint, 0x80);
  EXPECT_EQ(c.call(c.logged() - 1).value, 0u) << "zero-length status IN";
  // Before the status stage completes the device is still in the default state.
  EXPECT_EQ(dev.usb->device().state(), DeviceState::kDefault);
  EXPECT_EQ(dev.usb->device().address(), 0);
  std::uint8_t buf[64];
  std::size_t n = 99;
  EXPECT_EQ(c.in_token(0x80, buf, n), Handshake::kAck);
  EXPECT_EQ(n, 0u);
  EXPECT_EQ(dev.usb->device().state(), DeviceState::kAddressed);
  EXPECT_EQ(dev.usb->device().address(), 42);
  // SET_ADDRESS(0) from the addressed state returns to the default state.
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetAddress, 0, 0, 0)).ok());
  EXPECT_EQ(dev.usb->device().state(), DeviceState::kDefault);
}

TEST(UsbControl, SetAddressRefusals) {
  UsbTestDevice dev;
  dev.controller.bus_reset();
  // Address > 127, wIndex != 0, IN direction: STALL, state unchanged.
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetAddress, 128, 0, 0)).stalled());
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetAddress, 5, 1, 0)).stalled());
  EXPECT_TRUE(dev.control(std_req(true, Recipient::kDevice, request::kSetAddress, 5, 0, 0)).stalled());
  EXPECT_EQ(dev.usb->device().state(), DeviceState::kDefault);
  // In the configured state SET_ADDRESS is not defined: STALL.
  dev.enumerate();
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetAddress, 9, 0, 0)).stalled());
  EXPECT_EQ(dev.usb->device().address(), 5);
}

TEST(UsbControl, ConfigurationOpensAndClosesTheEndpoints) {
  UsbTestDevice dev;
  FakeController& c = dev.controller;
  c.bus_reset();
  // Default state: GET/SET_CONFIGURATION are refused.
  EXPECT_TRUE(dev.control(std_req(true, Recipient::kDevice, request::kGetConfiguration, 0, 0, 1)).stalled());
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetConfiguration, 1, 0, 0)).stalled());
  ASSERT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetAddress, 3, 0, 0)).ok());
  Bytes in;
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kDevice, request::kGetConfiguration, 0, 0, 1), {}, &in).ok());
  EXPECT_EQ(in, Bytes{0});
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetConfiguration, 2, 0, 0)).stalled());
  ASSERT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetConfiguration, 1, 0, 0)).ok());
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kDevice, request::kGetConfiguration, 0, 0, 1), {}, &in).ok());
  EXPECT_EQ(in, Bytes{1});
  struct Expected {
    EndpointAddress ep;
    EndpointType type;
    std::uint16_t max_packet;
  };
  for (const Expected& e : {Expected{0x81, EndpointType::kInterrupt, 16}, Expected{0x02, EndpointType::kBulk, 64},
                            Expected{0x82, EndpointType::kBulk, 64}, Expected{0x83, EndpointType::kInterrupt, 64}}) {
    EXPECT_TRUE(c.endpoint_open(e.ep)) << int(e.ep);
    EXPECT_EQ(c.endpoint_type(e.ep), e.type) << int(e.ep);
    EXPECT_EQ(c.max_packet(e.ep), e.max_packet) << int(e.ep);
  }
  EXPECT_TRUE(c.transfer_active(0x02)) << "CDC bulk OUT armed at configuration";
  EXPECT_FALSE(c.endpoint_open(0x01));
  EXPECT_FALSE(c.endpoint_open(0x03));
  ASSERT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetConfiguration, 0, 0, 0)).ok());
  EXPECT_EQ(dev.usb->device().state(), DeviceState::kAddressed);
  for (const int ep : {0x81, 0x02, 0x82, 0x83}) EXPECT_FALSE(c.endpoint_open(static_cast<EndpointAddress>(ep))) << ep;
}

TEST(UsbControl, GetStatusOfDeviceInterfaceAndEndpoint) {
  UsbTestDevice dev;
  dev.enumerate();
  FakeController& c = dev.controller;
  Bytes in;
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kDevice, request::kGetStatus, 0, 0, 2), {}, &in).ok());
  EXPECT_EQ(in, (Bytes{1, 0})) << "self-powered, no remote wakeup";
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kInterface, request::kGetStatus, 0, 2, 2), {}, &in).ok());
  EXPECT_EQ(in, (Bytes{0, 0}));
  EXPECT_TRUE(dev.control(std_req(true, Recipient::kInterface, request::kGetStatus, 0, 5, 2)).stalled());
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kEndpoint, request::kGetStatus, 0, 0x83, 2), {}, &in).ok());
  EXPECT_EQ(in, (Bytes{0, 0}));
  // ENDPOINT_HALT on 0x83: reported, applied to the controller, cleared.
  ASSERT_TRUE(dev.control(std_req(false, Recipient::kEndpoint, request::kSetFeature, 0, 0x83, 0)).ok());
  EXPECT_TRUE(c.endpoint_halted(0x83));
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kEndpoint, request::kGetStatus, 0, 0x83, 2), {}, &in).ok());
  EXPECT_EQ(in, (Bytes{1, 0}));
  ASSERT_TRUE(dev.control(std_req(false, Recipient::kEndpoint, request::kClearFeature, 0, 0x83, 0)).ok());
  EXPECT_FALSE(c.endpoint_halted(0x83));
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kEndpoint, request::kGetStatus, 0, 0x83, 2), {}, &in).ok());
  EXPECT_EQ(in, (Bytes{0, 0}));
  // EP0: status readable, CLEAR_FEATURE accepted, SET_FEATURE(HALT) refused.
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kEndpoint, request::kGetStatus, 0, 0x80, 2), {}, &in).ok());
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kEndpoint, request::kClearFeature, 0, 0x00, 0)).ok());
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kEndpoint, request::kSetFeature, 0, 0x80, 0)).stalled());
  // Endpoints that do not exist: 0x84, 0x01 (OUT 1 is not used), 0x03.
  for (const int ep : {0x84, 0x01, 0x03}) {
    EXPECT_TRUE(dev.control(std_req(true, Recipient::kEndpoint, request::kGetStatus, 0, static_cast<std::uint16_t>(ep), 2)).stalled()) << ep;
  }
  // Unknown feature selector on an endpoint.
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kEndpoint, request::kSetFeature, 5, 0x83, 0)).stalled());
}

TEST(UsbControl, EndpointRequestsBeforeConfigurationOnlyReachEp0) {
  UsbTestDevice dev;
  dev.controller.bus_reset();
  ASSERT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetAddress, 3, 0, 0)).ok());
  EXPECT_TRUE(dev.control(std_req(true, Recipient::kEndpoint, request::kGetStatus, 0, 0x80, 2)).ok());
  EXPECT_TRUE(dev.control(std_req(true, Recipient::kEndpoint, request::kGetStatus, 0, 0x81, 2)).stalled());
  EXPECT_TRUE(dev.control(std_req(true, Recipient::kInterface, request::kGetStatus, 0, 0, 2)).stalled());
}

TEST(UsbControl, WrongLengthsStall) {
  UsbTestDevice dev;
  dev.enumerate();
  // Fixed-size replies asked with another wLength, and no-data requests with
  // a data stage: each STALLs, and the next request works.
  const SetupPacket bad[] = {
      std_req(true, Recipient::kDevice, request::kGetStatus, 0, 0, 1),
      std_req(true, Recipient::kDevice, request::kGetStatus, 0, 0, 3),
      std_req(true, Recipient::kDevice, request::kGetConfiguration, 0, 0, 2),
      std_req(true, Recipient::kInterface, request::kGetInterface, 0, 4, 2),
      std_req(true, Recipient::kEndpoint, request::kGetStatus, 0, 0x82, 4),
      std_req(false, Recipient::kDevice, request::kSetConfiguration, 1, 0, 1),
      std_req(false, Recipient::kEndpoint, request::kClearFeature, 0, 0x82, 2),
      std_req(false, Recipient::kInterface, request::kSetInterface, 0, 4, 1),
  };
  for (const SetupPacket& s : bad) {
    EXPECT_TRUE(dev.control(s, Bytes(s.length, 0)).stalled()) << "request " << int(s.request) << " wLength " << s.length;
    EXPECT_TRUE(dev.control(std_req(true, Recipient::kDevice, request::kGetStatus, 0, 0, 2)).ok());
  }
  EXPECT_EQ(dev.usb->device().state(), DeviceState::kConfigured);
}

TEST(UsbControl, UnsupportedRequestsStall) {
  UsbTestDevice dev;
  dev.enumerate();
  const SetupPacket unsupported[] = {
      UsbTestDevice::get_descriptor(descriptor::kDeviceQualifier, 0, 10),  // full speed only
      UsbTestDevice::get_descriptor(descriptor::kOtherSpeedConfiguration, 0, 9),
      UsbTestDevice::get_descriptor(descriptor::kConfiguration, 1, 9),  // only configuration index 0
      UsbTestDevice::get_descriptor(descriptor::kDevice, 1, 18),
      UsbTestDevice::get_descriptor(0x0F, 0, 5),  // BOS: not a USB 2.0 full-speed device's
      std_req(false, Recipient::kDevice, request::kSetDescriptor, 0x0100, 0, 0),
      std_req(true, Recipient::kEndpoint, request::kSynchFrame, 0, 0x83, 2),
      std_req(false, Recipient::kDevice, request::kSetFeature, kFeatureRemoteWakeup, 0, 0),
      std_req(false, Recipient::kDevice, request::kSetFeature, kFeatureTestMode, 0x0100, 0),
      std_req(false, Recipient::kDevice, request::kClearFeature, kFeatureRemoteWakeup, 0, 0),
      std_req(true, Recipient::kOther, request::kGetStatus, 0, 0, 2),
      {request_type(true, RequestKind::kVendor, Recipient::kDevice), 0x01, 0, 0, 8},
      {request_type(true, RequestKind::kClass, Recipient::kInterface), 0x01, 0, 9, 8},  // no interface 9
      {request_type(true, RequestKind::kClass, Recipient::kDevice), 0x01, 0, 0, 8},
      {0x80, 0x77, 0, 0, 8},  // unknown standard request
  };
  for (const SetupPacket& s : unsupported) {
    const ControlResult r = dev.control(s, Bytes(s.is_in() ? 0 : s.length, 0));
    EXPECT_TRUE(r.stalled()) << "type " << int(s.request_type) << " request " << int(s.request);
    EXPECT_TRUE(dev.controller.control_stalled());
  }
  // The stall ends with the next SETUP.
  EXPECT_TRUE(dev.control(std_req(true, Recipient::kDevice, request::kGetStatus, 0, 0, 2)).ok());
  EXPECT_FALSE(dev.controller.control_stalled());
}

TEST(UsbControl, ZeroLengthPacketOnlyWhenTheReplyIsAMultipleOf64AndShort) {
  UsbTestDevice dev;
  dev.enumerate();
  FakeController& c = dev.controller;
  // The name of DFU alternate 1, "HADYNET model in use, read only", is 31
  // characters: 64 bytes.
  std::uint8_t buf[64];
  std::size_t n = 0;
  c.setup(UsbTestDevice::get_descriptor(descriptor::kString, composite::string_index::kDfuRunningModel, 255));
  ASSERT_EQ(c.in_token(0x80, buf, n), Handshake::kAck);
  EXPECT_EQ(n, 64u);
  EXPECT_EQ(buf[0], 64);
  ASSERT_EQ(c.in_token(0x80, buf, n), Handshake::kAck) << "a ZLP ends the 64-byte reply to wLength 255";
  EXPECT_EQ(n, 0u);
  EXPECT_EQ(c.in_token(0x80, buf, n), Handshake::kNak) << "then the device waits for the status stage";
  EXPECT_EQ(c.out_token(0x00, {}), Handshake::kAck);
  EXPECT_EQ(dev.usb->device().control_stage(), ControlStage::kIdle);

  // wLength 64: the reply fills it exactly, no ZLP.
  c.setup(UsbTestDevice::get_descriptor(descriptor::kString, composite::string_index::kDfuRunningModel, 64));
  ASSERT_EQ(c.in_token(0x80, buf, n), Handshake::kAck);
  EXPECT_EQ(n, 64u);
  EXPECT_EQ(c.in_token(0x80, buf, n), Handshake::kNak);
  EXPECT_EQ(c.out_token(0x00, {}), Handshake::kAck);

  // The configuration (more than 64 bytes) in 64-byte packets, bytes exact;
  // its length is not a multiple of 64, so no ZLP either way.
  static_assert(composite::kConfigurationSize % 64 != 0);
  std::vector<std::size_t> packets;
  c.setup(UsbTestDevice::get_descriptor(descriptor::kConfiguration, 0, 1024));
  const Bytes config = drain_in(c, 0x80, &packets);
  EXPECT_EQ(config, Bytes(composite::kConfiguration.begin(), composite::kConfiguration.end()));
  for (std::size_t i = 0; i + 1 < packets.size(); ++i) EXPECT_EQ(packets[i], 64u);
  EXPECT_LT(packets.back(), 64u);
  EXPECT_EQ(c.out_token(0x00, {}), Handshake::kAck);
}

TEST(UsbControl, ANewSetupAbortsTheTransferInProgress) {
  UsbTestDevice dev;
  dev.enumerate();
  FakeController& c = dev.controller;
  std::uint8_t buf[64];
  std::size_t n = 0;
  c.setup(UsbTestDevice::get_descriptor(descriptor::kConfiguration, 0, 1024));
  ASSERT_EQ(c.in_token(0x80, buf, n), Handshake::kAck);
  ASSERT_EQ(n, 64u);
  Bytes in;
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kDevice, request::kGetStatus, 0, 0, 2), {}, &in).ok());
  EXPECT_EQ(in, (Bytes{1, 0}));
}

TEST(UsbControl, AlternateSettingsOfTheDfuInterface) {
  UsbTestDevice dev;
  dev.enumerate();
  Bytes in;
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kInterface, request::kGetInterface, 0, 4, 1), {}, &in).ok());
  EXPECT_EQ(in, Bytes{0});
  ASSERT_TRUE(dev.control(std_req(false, Recipient::kInterface, request::kSetInterface, 1, 4, 0)).ok());
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kInterface, request::kGetInterface, 0, 4, 1), {}, &in).ok());
  EXPECT_EQ(in, Bytes{1});
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kInterface, request::kSetInterface, 2, 4, 0)).stalled());
  // Interfaces with one setting accept alternate 0 only.
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kInterface, request::kSetInterface, 0, 0, 0)).ok());
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kInterface, request::kSetInterface, 1, 2, 0)).stalled());
  EXPECT_TRUE(dev.control(std_req(false, Recipient::kInterface, request::kSetInterface, 0, 5, 0)).stalled());
  // SET_CONFIGURATION resets alternates to 0.
  ASSERT_TRUE(dev.control(std_req(false, Recipient::kDevice, request::kSetConfiguration, 1, 0, 0)).ok());
  ASSERT_TRUE(dev.control(std_req(true, Recipient::kInterface, request::kGetInterface, 0, 4, 1), {}, &in).ok());
  EXPECT_EQ(in, Bytes{0});
}

TEST(UsbControl, BusResetReturnsToTheDefaultState) {
  UsbTestDevice dev;
  dev.enumerate();
  ASSERT_TRUE(dev.control(std_req(false, Recipient::kEndpoint, request::kSetFeature, 0, 0x82, 0)).ok());
  dev.controller.suspend();
  EXPECT_TRUE(dev.usb->device().suspended());
  dev.controller.bus_reset();
  EXPECT_EQ(dev.usb->device().state(), DeviceState::kDefault);
  EXPECT_EQ(dev.usb->device().address(), 0);
  EXPECT_FALSE(dev.usb->device().suspended());
  EXPECT_FALSE(dev.usb->device().endpoint_halted(0x82));
  EXPECT_TRUE(dev.control(std_req(true, Recipient::kDevice, request::kGetConfiguration, 0, 0, 1)).stalled());
  // Descriptors are readable in the default state (hosts read the device
  // descriptor before SET_ADDRESS).
  EXPECT_TRUE(dev.control(UsbTestDevice::get_descriptor(descriptor::kDevice, 0, 64)).ok());
  dev.enumerate();
  EXPECT_TRUE(dev.controller.transfer_active(0x02));
}

TEST(UsbControl, SuspendAndResumeAreTracked) {
  UsbTestDevice dev;
  dev.enumerate();
  dev.controller.suspend();
  EXPECT_TRUE(dev.usb->device().suspended());
  dev.controller.resume();
  EXPECT_FALSE(dev.usb->device().suspended());
  EXPECT_EQ(dev.usb->device().state(), DeviceState::kConfigured);
}

}  // namespace
}  // namespace hadynet::usb::testing
