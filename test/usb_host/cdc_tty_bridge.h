// The kernel's cdc-acm driver, as far as a tool on /dev/ttyACM<n> sees it:
// a pty whose master side this bridge connects to the CDC data interface's
// bulk endpoints of an emulated device. Bytes the tool writes to the tty go
// out as bulk OUT packets (<= max packet; a NAK keeps them queued: the
// device's flow control reaches the tool as a full tty); bulk IN packets
// are written to the tty. pump() is called under the bus lock by the node's
// pump; hang_up() closes the master (the tool's reads then fail with EIO or
// end), as the kernel hangs up the tty of a device that left.
#ifndef HADYNET_TEST_USB_HOST_CDC_TTY_BRIDGE_H_
#define HADYNET_TEST_USB_HOST_CDC_TTY_BRIDGE_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "test/usb_host/urb_engine.h"

namespace hadynet::usb::host_testing {

class CdcTtyBridge {
 public:
  // A new pty (slave in raw mode, no echo) for `out_ep`/`in_ep`; null and
  // `error` on failure. `slave_path`: "/dev/pts/N".
  static std::unique_ptr<CdcTtyBridge> open(std::uint8_t out_ep, std::uint8_t in_ep, std::string& slave_path,
                                            std::string& error);
  ~CdcTtyBridge();
  CdcTtyBridge(const CdcTtyBridge&) = delete;
  CdcTtyBridge& operator=(const CdcTtyBridge&) = delete;

  void pump(UrbEngine& engine);
  void hang_up();

 private:
  CdcTtyBridge(int master, int slave, std::uint8_t out_ep, std::uint8_t in_ep)
      : master_(master), slave_(slave), out_ep_(out_ep), in_ep_(in_ep) {}
  int master_ = -1;
  int slave_ = -1;  // kept open so the pty survives the tool's close (as a tty node does)
  std::uint8_t out_ep_, in_ep_;
  std::vector<std::uint8_t> to_device_;
  std::vector<std::uint8_t> to_host_;
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_CDC_TTY_BRIDGE_H_
