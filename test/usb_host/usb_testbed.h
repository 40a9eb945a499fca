// A USB bus for the real libusb, hidapi's libusb backend, dfu-util and the
// hadynet tools, made of one umockdev testbed per test process: emulated
// devices (emulated_device.h) are plugged at an address and unplugged, and
// each becomes a usbdevfs node /dev/bus/usb/001/DDD whose ioctls (URBs) the
// fixture plays into the device's FakeController. No privileges needed; the
// process must run under `umockdev-wrapper` (LD_PRELOAD), which redirects
// /sys and /dev to the testbed. Child processes started with the inherited
// environment (LD_PRELOAD and UMOCKDEV_DIR) see the same bus.
//
//   UsbTestbed bus;                          // sets $UMOCKDEV_DIR
//   auto hand = std::make_shared<HandDevice>();
//   ASSERT_TRUE(bus.plug(2, hand)) << bus.error();
//   bus.locked([&] { hand->publish(record); });  // device side, then pump
//
// What the fixture does in place of the kernel:
//   * plug(): enumeration through the device's controller and the sysfs
//     device made from its answers (enumeration.h), then the node (an "add"
//     uevent);
//   * the usbdevfs ioctls and URBs (usbdevfs_node.h, urb_engine.h);
//   * a device whose attached() turns false (a reboot, a DfuSe "leave")
//     leaves the bus: its pending URBs complete with -ENODEV at once and
//     later ioctls fail with ENODEV; the sysfs removal ("remove" uevent) and
//     the on_left callback follow in the next pump() of a test thread;
//   * optionally the kernel's cdc-acm driver: a pty /dev/ttyACM<n> bridged
//     to the device's CDC bulk endpoints (attach_cdc_tty, cdc_tty_bridge.h).
//
// Threads and the pump: umockdev runs the ioctl handler on its worker
// thread; tests call pump()/locked() from theirs. Every call into a device
// (its controller's host side, service()) happens under one bus lock, so an
// EmulatedDevice needs no locking of its own. The pump = for each device
// service() once, then retry its pending URBs in order. It runs on every
// ioctl of a node and in pump()/locked(). libusb waits for URBs by polling
// the node for POLLOUT, and a umockdev node is a unix socket, always
// writable: libusb's event loop calls REAPURBNDELAY continuously while a
// transfer is in flight, and every call pumps the device. A test that runs
// a client in a CHILD process must still call pump() while it waits (the
// device's own work, telemetry, unplugs): child_process.h does.
#ifndef HADYNET_TEST_USB_HOST_USB_TESTBED_H_
#define HADYNET_TEST_USB_HOST_USB_TESTBED_H_

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "test/usb_host/emulated_device.h"
#include "test/usb_host/enumeration.h"
#include "test/usb_host/urb_engine.h"

namespace hadynet::usb::host_testing {

struct UsbNodeStats {
  std::uint64_t ioctls = 0;
  std::uint64_t urbs_submitted = 0;
  std::uint64_t urbs_reaped = 0;
  std::uint64_t urbs_discarded = 0;
  std::uint64_t naks = 0;  // NAKed tokens (each retry counts)
  std::uint64_t unknown_ioctls = 0;
  unsigned long last_unknown_ioctl = 0;  // its request number
};

class UsbTestbed {
 public:
  static constexpr std::uint8_t kBusnum = 1;

  // Creates the testbed (sets $UMOCKDEV_DIR for this process and its
  // children) with an empty /dev/bus/usb. ok() false (error() says why)
  // outside umockdev-wrapper.
  UsbTestbed();
  // Destroy only after every libusb context of this process that saw a
  // device has exited, and after the children are gone.
  ~UsbTestbed();
  UsbTestbed(const UsbTestbed&) = delete;
  UsbTestbed& operator=(const UsbTestbed&) = delete;

  bool ok() const noexcept { return error_.empty(); }
  const std::string& error() const noexcept { return error_; }

  // Enumerates `device` (started: UsbDevice::start done) at address
  // `devnum` (2..127, free) and adds its node and sysfs device. False (and
  // error() set; the bus unchanged) if enumeration or umockdev fails.
  bool plug(std::uint8_t devnum, std::shared_ptr<EmulatedDevice> device);
  // The device at `devnum` leaves the bus (as if the cable were pulled):
  // pending URBs -ENODEV, then the sysfs device is removed ("remove" uevent).
  // on_left is NOT called (the test did it). No-op if nothing is there.
  void unplug(std::uint8_t devnum);
  bool plugged(std::uint8_t devnum) const;
  // What enumeration read (empty EnumeratedDevice if nothing is there).
  EnumeratedDevice enumerated(std::uint8_t devnum) const;

  // Services every device and retries its URBs; then removes the devices
  // that left by themselves and calls on_left for each (this thread, bus
  // lock released: the callback may plug() a successor).
  void pump();
  // `fn` under the bus lock (device-side calls: publish, flash contents...),
  // then pump().
  void locked(const std::function<void()>& fn);
  // Called by pump() with the address of a device that left the bus by
  // itself (attached() false), after its removal. E.g. the hand's
  // DFU_DETACH (HandDevice::set_leave_on_detach): plug the ROM bootloader.
  void set_on_left(std::function<void(std::uint8_t devnum)> on_left);

  // ---- faults, for the next client transfer on `endpoint` (0x00: control) ----
  // Completes with -error_number without reaching the device (EPIPE: a
  // STALL; EPROTO/EILSEQ: a bus error).
  void fail_next_transfer(std::uint8_t devnum, std::uint8_t endpoint, int error_number);
  // The device's next IN data packet reaches the client cut to `bytes`.
  void short_next_in(std::uint8_t devnum, std::uint8_t endpoint, std::size_t bytes);
  // The transfer never completes (no handshake at all) until discarded: the
  // client's own time-out must end it.
  void hang_next_transfer(std::uint8_t devnum, std::uint8_t endpoint);

  // ---- the kernel's cdc-acm driver ----
  // A pty bridged to the CDC data interface's bulk endpoints (`out_ep`,
  // `in_ep`) of the device at `devnum`, visible as /dev/<tty_name>; returns
  // its path ("" and error() on failure). The bridge hangs up (the tty reads
  // EIO) when the device leaves. Do not claim the data interface through
  // libusb meanwhile.
  std::string attach_cdc_tty(std::uint8_t devnum, const std::string& tty_name, std::uint8_t out_ep,
                             std::uint8_t in_ep);

  // ---- observations ----
  UsbNodeStats stats(std::uint8_t devnum) const;
  PacketCounts packets(std::uint8_t devnum) const;  // ACKed data packets per endpoint
  bool has_pending(std::uint8_t devnum, std::uint8_t endpoint) const;

  struct Bus;  // the lock, the nodes, the devices that left (usb_testbed.cc)

 private:
  std::string error_;
  std::shared_ptr<Bus> bus_;
  void* testbed_ = nullptr;  // UMockdevTestbed*
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_USB_TESTBED_H_
