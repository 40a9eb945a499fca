// One device node /dev/bus/usb/BBB/DDD of the testbed: the usbdevfs ioctls
// a client (libusb, hidapi, dfu-util) issues, answered in place of the
// kernel, and the client's URBs queued on the device's UrbEngine.
//
// ioctls: GET_CAPABILITIES, SUBMITURB, REAPURBNDELAY (and REAPURB, which
// does not block here), DISCARDURB, CLAIMINTERFACE, RELEASEINTERFACE,
// SETINTERFACE, SETCONFIGURATION, CLEAR_HALT, RESETEP, RESET, GET_SPEED
// (full), GETDRIVER (ENODATA: no kernel driver), IOCTL and DISCONNECT_CLAIM
// (accepted: there are no drivers to detach). Interface claims are not
// tracked (no EBUSY between two handles). Anything else: ENOTTY, counted.
// URBs on one endpoint complete in submission order; a discarded URB
// completes with -ENOENT (bytes already moved stay moved, as on a real bus).
//
// Internal to the fixture (usb_testbed.cc); every member is called with the
// bus lock held.
#ifndef HADYNET_TEST_USB_HOST_USBDEVFS_NODE_H_
#define HADYNET_TEST_USB_HOST_USBDEVFS_NODE_H_

#include <cstdint>
#include <deque>
#include <memory>
#include <string>

#include "test/usb_host/emulated_device.h"
#include "test/usb_host/enumeration.h"
#include "test/usb_host/urb_engine.h"
#include "test/usb_host/usb_testbed.h"

typedef struct _UMockdevIoctlClient UMockdevIoctlClient;
typedef struct _UMockdevIoctlData UMockdevIoctlData;

namespace hadynet::usb::host_testing {

class CdcTtyBridge;

class UsbdevfsNode {
 public:
  UsbdevfsNode(std::shared_ptr<EmulatedDevice> device, EnumeratedDevice enumerated);
  ~UsbdevfsNode();
  UsbdevfsNode(const UsbdevfsNode&) = delete;
  UsbdevfsNode& operator=(const UsbdevfsNode&) = delete;

  // One ioctl of `client`: the result (>= 0) or -errno.
  int handle(UMockdevIoctlClient* client);
  // Drops the URBs of a client that closed the node.
  void client_vanished(UMockdevIoctlClient* client);
  // service(), the tty bridge, then every pending URB in submission order (a
  // URB waits while an earlier one on its endpoint is pending). Returns
  // false once the device has left the bus (by itself or unplugged).
  bool pump();
  // The device leaves the bus: pending URBs complete with -ENODEV and every
  // later ioctl but reaping fails with ENODEV.
  void leave();
  bool left() const noexcept { return left_; }

  UrbEngine& engine() noexcept { return engine_; }
  const EnumeratedDevice& enumerated() const noexcept { return enumerated_; }
  UsbNodeStats stats() const;
  // Whether a client URB on `ep` is waiting for the device.
  bool has_pending(EndpointAddress ep) const;
  // Real path of the sysfs bConfigurationValue (rewritten on SETCONFIGURATION).
  void set_configuration_attribute(std::string path) { configuration_attribute_ = std::move(path); }
  void set_bridge(std::unique_ptr<CdcTtyBridge> bridge);

 private:
  struct Urb {
    UMockdevIoctlClient* client = nullptr;  // ref
    UMockdevIoctlData* data = nullptr;      // ref: local copy of struct usbdevfs_urb
    UMockdevIoctlData* buffer = nullptr;    // ref or null: local copy of its buffer
    Transfer t;
  };
  static void release(Urb& u);
  int submit_urb(UMockdevIoctlClient* client, UMockdevIoctlData* arg);
  int reap_urb(UMockdevIoctlClient* client, UMockdevIoctlData* arg);
  int discard_urb(UMockdevIoctlClient* client, UMockdevIoctlData* arg);
  int reenumerate();
  void finish_all_pending(int status);
  void write_configuration_attribute() const;

  std::shared_ptr<EmulatedDevice> device_;
  UrbEngine engine_;
  EnumeratedDevice enumerated_;
  std::unique_ptr<CdcTtyBridge> bridge_;
  std::deque<Urb> pending_;
  std::deque<Urb> completed_;
  UsbNodeStats stats_;
  unsigned configuration_ = 0;
  std::string configuration_attribute_;
  bool left_ = false;
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_USBDEVFS_NODE_H_
