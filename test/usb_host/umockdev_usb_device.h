// The firmware's composite USB device (HadynetUsbDevice over the host
// backend FakeController) served to the real libusb, hidapi's libusb backend
// or dfu-util through umockdev: a usbdevfs node /dev/bus/usb/BBB/DDD whose
// ioctls (URBs) this fixture translates into FakeController transactions.
// No privileges needed; the process must run under `umockdev-wrapper`
// (LD_PRELOAD), which redirects /sys and /dev to the testbed.
//
//   UmockdevUsbDevice usb;                 // testbed, enumeration, device added
//   ASSERT_TRUE(usb.ok()) << usb.error();
//   libusb_init(&ctx); ... libusb_exit(ctx);  // libusb sees 1209:0001 on bus 1
//   usb.publish(record);                   // HID telemetry from the device side
//
// What the fixture does in place of the kernel:
//   * enumeration at construction, through the stack over EP0: bus reset,
//     GET_DESCRIPTOR(device), SET_ADDRESS(devnum), GET_DESCRIPTOR(config,
//     whole), the manufacturer/product/serial/configuration strings,
//     SET_CONFIGURATION(1). The sysfs attributes (`descriptors` = device +
//     configuration descriptor as read, busnum, devnum, speed 12,
//     bConfigurationValue, idVendor, ... ) are made from what the device
//     answered, never from the firmware's constants.
//   * usbdevfs ioctls: GET_CAPABILITIES, SUBMITURB, REAPURBNDELAY (and
//     REAPURB, which does not block here), DISCARDURB, CLAIMINTERFACE,
//     RELEASEINTERFACE, SETINTERFACE, SETCONFIGURATION, CLEAR_HALT, RESETEP,
//     RESET, GET_SPEED (full), GETDRIVER (ENODATA: no kernel driver),
//     IOCTL and DISCONNECT_CLAIM (accepted: there are no drivers to detach).
//     Interface claims are not tracked (no EBUSY between two handles).
//     Anything else: ENOTTY, counted in unknown_ioctls().
//   * URBs: control → SETUP, DATA and STATUS stages one packet at a time;
//     bulk/interrupt OUT → one out_token per max-packet packet (+ a ZLP when
//     USBDEVFS_URB_ZERO_PACKET asks and the last packet was full);
//     bulk/interrupt IN → in_token until a short packet or the URB buffer is
//     full (a packet larger than the room left: -EOVERFLOW). NAK keeps the URB
//     pending, where it stopped; STALL completes it with -EPIPE. URBs on one
//     endpoint complete in submission order. A discarded URB completes with
//     -ENOENT (bytes already moved stay moved, as on a real bus).
//
// Threads and the pump: umockdev runs the ioctl handler on its worker thread;
// the test thread calls publish()/pump(). The firmware stack is one context
// and not reentrant, so every call into it (FakeController host side,
// service(), publish()) happens under one mutex: never two at once. The pump
// = service() once, then retry every pending URB in order. It runs on every
// ioctl of the device node and in publish()/pump(). That is enough because
// libusb waits for URBs by polling the node for POLLOUT, and a umockdev node
// is a unix socket, always writable: libusb's event loop calls
// REAPURBNDELAY continuously while a transfer is in flight (busy, but short
// in tests), and every call pumps the device.
//
// Faults: fail_next_transfer() (a host-visible error on one URB, e.g. a
// STALL) and unplug(). Not yet: a device-side halt through the stack, a
// re-plug, suspend/resume.
#ifndef HADYNET_TEST_USB_HOST_UMOCKDEV_USB_DEVICE_H_
#define HADYNET_TEST_USB_HOST_UMOCKDEV_USB_DEVICE_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "firmware/app/period_record.h"
#include "hadynet_model_q15.h"

namespace hadynet::usb::host_testing {

using Q = model_q15::Model;

// The MCU unique ID the fixture's device reports (bytes as a board reads
// them) and its serial-number string.
inline constexpr std::array<std::uint8_t, 12> kFixtureUid = {0x20, 0x00, 0x3B, 0x00, 0x11, 0x51,
                                                             0x32, 0x30, 0x36, 0x39, 0x34, 0x38};
inline constexpr const char* kFixtureSerial = "20003B001151323036393438";
inline constexpr const char* kFixtureFirmwareVersion = "0.1.0-umockdev";

struct UmockdevUsbStats {
  std::uint64_t ioctls = 0;
  std::uint64_t urbs_submitted = 0;
  std::uint64_t urbs_reaped = 0;
  std::uint64_t urbs_discarded = 0;
  std::uint64_t naks = 0;  // NAKed tokens (each retry counts)
  std::uint64_t unknown_ioctls = 0;
  unsigned long last_unknown_ioctl = 0;  // its request number
};

class UmockdevUsbDevice {
 public:
  // Creates the testbed (sets $UMOCKDEV_DIR for this process), enumerates
  // the device, attaches the ioctl handler to /dev/bus/usb/<busnum>/<devnum>
  // and adds the sysfs device (an "add" uevent). On failure ok() is false
  // and error() says why; nothing else is valid then.
  explicit UmockdevUsbDevice(std::uint8_t busnum = 1, std::uint8_t devnum = 2);
  // Destroy only after every libusb context that saw the device has exited
  // (libusb_exit): the testbed's sysfs and sockets go away here. State the
  // worker thread may still touch is reference counted and outlives this.
  ~UmockdevUsbDevice();
  UmockdevUsbDevice(const UmockdevUsbDevice&) = delete;
  UmockdevUsbDevice& operator=(const UmockdevUsbDevice&) = delete;

  bool ok() const noexcept { return error_.empty(); }
  const std::string& error() const noexcept { return error_; }

  std::uint8_t busnum() const noexcept { return busnum_; }
  std::uint8_t devnum() const noexcept { return devnum_; }
  std::string devnode() const;  // "/dev/bus/usb/001/002"
  // What enumeration read from the device (and sysfs `descriptors` holds).
  const std::vector<std::uint8_t>& device_descriptor() const noexcept { return device_descriptor_; }
  const std::vector<std::uint8_t>& configuration_descriptor() const noexcept { return configuration_; }
  // The device's own serial and configuration (version) strings.
  std::string serial_number() const;
  std::string version_string() const;

  // ---- the device side (locked; any thread) ----
  // HadynetUsbDevice::publish, then the pump.
  void publish(const app::PeriodRecord<Q>& record);
  // service() and retry the pending URBs.
  void pump();
  UmockdevUsbStats stats() const;
  // ---- faults ----
  // The next URB submitted on `endpoint` (0x00 for control) completes with
  // -error_number without reaching the device: EPIPE looks like a STALL,
  // EPROTO/EILSEQ like a bus error, ETIMEDOUT like a lost handshake.
  void fail_next_transfer(std::uint8_t endpoint, int error_number);
  // The device leaves the bus: pending URBs complete with -ENODEV, every
  // later ioctl but reaping fails with ENODEV, and the sysfs device is
  // removed (a "remove" uevent for libusb's hotplug monitor). Irreversible.
  void unplug();

  // DFU_DETACH requests the device passed to its board hook (the fixture's
  // hook only counts them: nothing reboots).
  int detach_requests() const;

  struct State;  // the device, the pending URBs, the mutex (umockdev_usb_device.cc)

 private:
  std::string error_;
  std::uint8_t busnum_;
  std::uint8_t devnum_;
  std::vector<std::uint8_t> device_descriptor_;
  std::vector<std::uint8_t> configuration_;
  std::shared_ptr<State> state_;
  void* testbed_ = nullptr;  // UMockdevTestbed*
  void* handler_ = nullptr;  // UMockdevIoctlBase*
  std::string syspath_;      // the testbed's /sys/devices/.../<bus>-1
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_UMOCKDEV_USB_DEVICE_H_
