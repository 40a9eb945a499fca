// A USB device as the umockdev fixture (umockdev_usb_device.h) serves it:
// device-side code running on the host backend `FakeController`, whose host
// side (bus reset, SETUP, IN/OUT tokens) the fixture drives from the URBs a
// client (libusb, hidapi, dfu-util, the hadynet tools) submits.
//
// Implementations: the hand's composite device (HadynetUsbDevice) and the
// simulated STM32 ROM DfuSe bootloader (test/dfuse_sim/). Contract:
//   * before it is plugged into the fixture, the device side has started
//     (UsbDevice::start: controller initialised, connected); the fixture
//     then enumerates it (bus reset, SET_ADDRESS, descriptors,
//     SET_CONFIGURATION 1) through the controller like a host would;
//   * the fixture calls every method under its own lock, never two at once,
//     so implementations need no locking of their own;
//   * `attached()` turning false means the device left the bus by itself (a
//     DfuSe "leave", a reboot): the fixture then unplugs it (pending URBs
//     complete with -ENODEV, a "remove" uevent) as a kernel would.
#ifndef HADYNET_TEST_USB_HOST_EMULATED_DEVICE_H_
#define HADYNET_TEST_USB_HOST_EMULATED_DEVICE_H_

#include "firmware/usb/host/fake_controller.h"

namespace hadynet::usb::host_testing {

class EmulatedDevice {
 public:
  virtual ~EmulatedDevice() = default;
  // The host backend the device side runs on.
  virtual host::FakeController& controller() noexcept = 0;
  // Main-loop work of the device side (UsbDevice::service and the like);
  // the fixture calls it before retrying pending URBs.
  virtual void service() noexcept = 0;
  // False once the device has left the bus on its own.
  virtual bool attached() const noexcept { return true; }
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_EMULATED_DEVICE_H_
