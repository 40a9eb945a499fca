// The descriptor set, read over EP0 by GET_DESCRIPTOR like a host would, and
// checked by the test's own parser (descriptor_parser.cc) against USB 2.0,
// the IAD ECN, CDC, HID and DFU 1.1. All expectations are exact: descriptors
// are bytes.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "descriptor_parser.h"
#include "firmware/usb/composite_descriptors.h"
#include "usb_test_device.h"

namespace hadynet::usb::testing {
namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& e : v) s += "\n  " + e;
  return s;
}

Bytes read_descriptor(UsbTestDevice& dev, std::uint8_t type, std::uint8_t index, std::uint16_t length = 255,
                      std::uint16_t windex = 0) {
  Bytes in;
  const ControlResult r = dev.control(UsbTestDevice::get_descriptor(type, index, length, windex), {}, &in);
  EXPECT_TRUE(r.ok()) << "GET_DESCRIPTOR type " << int(type) << " index " << int(index);
  return in;
}

TEST(UsbDescriptors, DeviceDescriptorIsValidAndCarriesTheIdentity) {
  UsbTestDevice dev;
  dev.enumerate();
  const Bytes d = read_descriptor(dev, descriptor::kDevice, 0, 18);
  std::vector<std::string> errors;
  check_device_descriptor(d, errors);
  EXPECT_TRUE(errors.empty()) << join(errors);
  ASSERT_EQ(d.size(), 18u);
  // pid.codes test VID:PID 1209:0001 (usb_identity.h, docs/usb.md).
  EXPECT_EQ(d[8] | (d[9] << 8), 0x1209);
  EXPECT_EQ(d[10] | (d[11] << 8), 0x0001);
  EXPECT_EQ(d[7], 64) << "EP0 max packet";
}

TEST(UsbDescriptors, ConfigurationParsesAsValidUsb2) {
  UsbTestDevice dev;
  dev.enumerate();
  // First the 9-byte header (as hosts do), then wTotalLength bytes.
  const Bytes head = read_descriptor(dev, descriptor::kConfiguration, 0, 9);
  ASSERT_EQ(head.size(), 9u);
  const std::uint16_t total = static_cast<std::uint16_t>(head[2] | (head[3] << 8));
  const Bytes config = read_descriptor(dev, descriptor::kConfiguration, 0, total);
  ASSERT_EQ(config.size(), total);

  std::vector<std::string> errors;
  const ParsedConfiguration c = parse_configuration(config, errors);
  EXPECT_TRUE(errors.empty()) << join(errors);
  EXPECT_EQ(c.num_interfaces, 5);
  EXPECT_EQ(c.value, 1);

  // IAD: CDC over interfaces 0..1 (comm + data).
  ASSERT_EQ(c.iads.size(), 1u);
  EXPECT_EQ(c.iads[0].first_interface, 0);
  EXPECT_EQ(c.iads[0].count, 2);
  EXPECT_EQ(c.iads[0].cls, 0x02);
  EXPECT_EQ(c.iads[0].subclass, 0x02);

  // The endpoint plan: EP0 + 3 numbers (IN 1, 2, 3; OUT 2).
  std::set<std::uint8_t> addresses;
  for (const ParsedInterface& f : c.interfaces) {
    for (const ParsedEndpoint& e : f.endpoints) addresses.insert(e.address);
  }
  EXPECT_EQ(addresses, (std::set<std::uint8_t>{0x81, 0x02, 0x82, 0x83}));

  // Per interface: class triple and class-specific descriptors.
  ASSERT_EQ(c.interfaces.size(), 6u);  // 5 interfaces, the DFU-mode one with 2 alternates
  const ParsedInterface& comm = c.interfaces[0];
  EXPECT_EQ((std::array<int, 3>{comm.cls, comm.subclass, comm.protocol}), (std::array<int, 3>{2, 2, 0}));
  ASSERT_EQ(comm.class_descriptors.size(), 4u) << "CDC header, call management, ACM, union";
  EXPECT_EQ(comm.class_descriptors[0][2], 0x00);  // header
  EXPECT_EQ(comm.class_descriptors[3][2], 0x06);  // union
  EXPECT_EQ(comm.class_descriptors[3][3], 0);     // control interface
  EXPECT_EQ(comm.class_descriptors[3][4], 1);     // data interface
  EXPECT_EQ(c.interfaces[1].cls, 0x0A);
  const ParsedInterface& hid = c.interfaces[2];
  EXPECT_EQ(hid.cls, 0x03);
  ASSERT_EQ(hid.class_descriptors.size(), 1u);
  EXPECT_EQ(hid.class_descriptors[0][1], 0x21);
  ASSERT_EQ(hid.endpoints.size(), 1u);
  EXPECT_EQ(hid.endpoints[0].max_packet, 64);
  // DFU: runtime (protocol 1) and DFU mode (protocol 2) with 2 alternates,
  // each followed by a 9-byte functional descriptor.
  const ParsedInterface& runtime = c.interfaces[3];
  EXPECT_EQ((std::array<int, 3>{runtime.cls, runtime.subclass, runtime.protocol}), (std::array<int, 3>{0xFE, 1, 1}));
  ASSERT_EQ(runtime.class_descriptors.size(), 1u);
  EXPECT_EQ(runtime.class_descriptors[0].size(), 9u);
  EXPECT_NE(runtime.class_descriptors[0][2] & dfu::kWillDetach, 0);
  for (int alt = 0; alt < 2; ++alt) {
    const ParsedInterface& mode = c.interfaces[4 + alt];
    EXPECT_EQ(mode.number, 4);
    EXPECT_EQ(mode.alternate, alt);
    EXPECT_EQ(mode.protocol, 2);
    ASSERT_EQ(mode.class_descriptors.size(), 1u);
    const Bytes& f = mode.class_descriptors[0];
    ASSERT_EQ(f.size(), 9u);
    // bitCanDnload | bitCanUpload | bitManifestationTolerant, not bitWillDetach.
    EXPECT_EQ(f[2], 0x07);
    EXPECT_EQ(f[5] | (f[6] << 8), kDfuTransferSize);
    EXPECT_EQ(f[7] | (f[8] << 8), 0x0110);
  }
}

TEST(UsbDescriptors, EveryStringIndexResolves) {
  UsbTestDevice dev;
  dev.enumerate();
  const Bytes langids = read_descriptor(dev, descriptor::kString, 0);
  EXPECT_EQ(langids, (Bytes{4, 3, 0x09, 0x04}));

  std::vector<std::string> errors;
  const ParsedConfiguration c =
      parse_configuration(Bytes(composite::kConfiguration.begin(), composite::kConfiguration.end()), errors);
  const Bytes d = read_descriptor(dev, descriptor::kDevice, 0, 18);
  std::set<std::uint8_t> indices(c.string_indices.begin(), c.string_indices.end());
  indices.insert({d[14], d[15], d[16]});
  EXPECT_EQ(indices.size(), 10u) << "strings 1..10 all referenced";
  for (const std::uint8_t i : indices) {
    const std::string text = parse_string_descriptor(read_descriptor(dev, descriptor::kString, i, 255, 0x0409), errors);
    EXPECT_FALSE(text.empty()) << "string " << int(i);
  }
  // String 11, the DFU status description GETSTATUS names in iString:
  // resolves, empty while there is nothing to describe.
  EXPECT_EQ(parse_string_descriptor(
                read_descriptor(dev, descriptor::kString, composite::string_index::kDfuStatus, 255, 0x0409), errors),
            "");
  EXPECT_TRUE(errors.empty()) << join(errors);
  // An index past the table: STALL.
  EXPECT_TRUE(dev.control(UsbTestDevice::get_descriptor(descriptor::kString, 12, 255, 0x0409)).stalled());
}

TEST(UsbDescriptors, SerialIsTheUniqueIdAndVersionNamesTheRunningModel) {
  UsbTestDevice dev;  // no image in the slots: the factory model runs
  dev.enumerate();
  std::vector<std::string> errors;
  const Bytes d = read_descriptor(dev, descriptor::kDevice, 0, 18);
  EXPECT_EQ(parse_string_descriptor(read_descriptor(dev, descriptor::kString, d[16]), errors), kTestUidHex);
  EXPECT_EQ(parse_string_descriptor(read_descriptor(dev, descriptor::kString, d[14]), errors), "HADYNET project");
  char hash[17];
  std::snprintf(hash, sizeof(hash), "%016llx", static_cast<unsigned long long>(Q::kModelHash));
  EXPECT_EQ(parse_string_descriptor(read_descriptor(dev, descriptor::kString, composite::string_index::kVersion),
                                    errors),
            std::string("fw 0.1.0 model ") + hash + " (factory)");
  EXPECT_TRUE(errors.empty()) << join(errors);
}

}  // namespace
}  // namespace hadynet::usb::testing
