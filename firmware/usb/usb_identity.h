// THE one place for the device's USB identity (docs/usb.md).
//
// VID:PID 1209:0001 is pid.codes' *test* PID (vendor 0x1209 is pid.codes,
// the open-source hardware registry): for development and tests only. A
// device that leaves the lab needs its own PID from pid.codes; change it
// here, nowhere else (the host tools' udev rules and filters must follow).
#ifndef HADYNET_FIRMWARE_USB_USB_IDENTITY_H_
#define HADYNET_FIRMWARE_USB_USB_IDENTITY_H_

#include <cstdint>

namespace hadynet::usb {

struct UsbIdentity {
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::uint16_t device_release_bcd = 0;  // bcdDevice
  const char* manufacturer = "";
  const char* product = "";
};

inline constexpr UsbIdentity kHadynetUsbIdentity{
    0x1209,  // pid.codes
    0x0001,  // pid.codes test PID (development only)
    0x0100,  // device release 1.00
    "HADYNET project",
    "HADYNET forearm",
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_USB_IDENTITY_H_
