// What the kernel does when a device appears, done by the fixture through
// the device's controller: bus reset, GET_DESCRIPTOR(device),
// SET_ADDRESS(devnum), GET_DESCRIPTOR(configuration, 9 then whole), the
// manufacturer/product/serial/configuration strings, SET_CONFIGURATION.
// The sysfs record (umockdev-record's text format) is made from what the
// device answered, never from the firmware's constants.
#ifndef HADYNET_TEST_USB_HOST_ENUMERATION_H_
#define HADYNET_TEST_USB_HOST_ENUMERATION_H_

#include <cstdint>
#include <string>
#include <vector>

#include "test/usb_host/urb_engine.h"

namespace hadynet::usb::host_testing {

struct EnumeratedDevice {
  std::uint8_t busnum = 0;
  std::uint8_t devnum = 0;
  std::vector<std::uint8_t> device_descriptor;  // 18 bytes as read
  std::vector<std::uint8_t> configuration;      // the whole configuration descriptor as read
  std::string manufacturer, product, serial, configuration_name;  // ASCII; empty when absent or refused

  std::string devnode() const;  // "/dev/bus/usb/001/002"
  std::string syspath() const;  // "/sys/devices/pci0000:00/0000:00:14.0/usb1/1-<devnum>"
  // Whether the configuration declares alternate `alt` of `interface`.
  bool has_alternate(unsigned interface, unsigned alt) const;
};

// Enumerates the device behind `engine` at address `devnum`. Returns "" on
// success, else what failed.
std::string enumerate(UrbEngine& engine, std::uint8_t busnum, std::uint8_t devnum, EnumeratedDevice& out);

// The sysfs device as `umockdev-record` would write it (kernel attribute
// formats: hex without 0x for ids and classes, "%2d" for bNumInterfaces).
std::string sysfs_record(const EnumeratedDevice& d);

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_ENUMERATION_H_
