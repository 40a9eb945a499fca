// A USB function (a class driver: CDC-ACM, HID, DFU) as UsbDevice sees it.
// UsbDevice owns EP0 and the standard requests; it routes to a function the
// class requests addressed to the function's interfaces or endpoints, the
// standard GET_DESCRIPTOR addressed to its interface (HID), alternate
// settings, the completions of its endpoints, and service() calls.
//
// Every call comes from the one context the seam defines (device_controller.h).
#ifndef HADYNET_FIRMWARE_USB_USB_FUNCTION_H_
#define HADYNET_FIRMWARE_USB_USB_FUNCTION_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/usb/device_controller.h"
#include "firmware/usb/usb_spec.h"

namespace hadynet::usb {

// The control buffer: the largest data stage the device accepts or sends in
// one request (DFU wTransferSize, the configuration descriptor). Bytes.
inline constexpr std::size_t kControlBufferSize = 256;

// A function's answer to a SETUP packet.
struct ControlReply {
  enum class Kind : std::uint8_t {
    kStall,    // refuse: STALL the data or status stage
    kAck,      // no data stage (wLength 0): the status stage follows
    kDataIn,   // `size` bytes written to the buffer; the stack sends min(size, wLength)
    kDataOut,  // accept the OUT data stage (wLength bytes, fits the buffer): control_out() follows
  };
  Kind kind = Kind::kStall;
  std::uint16_t size = 0;

  static constexpr ControlReply stall() noexcept { return {Kind::kStall, 0}; }
  static constexpr ControlReply ack() noexcept { return {Kind::kAck, 0}; }
  static constexpr ControlReply data_in(std::size_t n) noexcept {
    return {Kind::kDataIn, static_cast<std::uint16_t>(n)};
  }
  static constexpr ControlReply data_out() noexcept { return {Kind::kDataOut, 0}; }
};

class UsbFunction {
 public:
  virtual bool owns_interface(std::uint8_t interface) const noexcept = 0;
  virtual bool owns_endpoint(EndpointAddress ep) const noexcept = 0;

  // A SETUP addressed to this function (class requests to its interfaces or
  // endpoints; standard GET_DESCRIPTOR to its interface). `buffer` is the
  // control buffer (kControlBufferSize bytes); for kDataIn the reply is
  // written there.
  virtual ControlReply control_setup(const SetupPacket& setup, std::span<std::uint8_t> buffer) noexcept = 0;
  // The OUT data stage of a request accepted with kDataOut: `data` holds what
  // the host sent (at most wLength bytes). true: acknowledge; false: STALL.
  virtual bool control_out(const SetupPacket& setup, std::span<const std::uint8_t> data) noexcept {
    (void)setup;
    (void)data;
    return false;
  }
  // The status stage of an accepted request completed: the host has seen
  // success (DFU_DETACH acts here).
  virtual void control_complete(const SetupPacket& setup) noexcept { (void)setup; }

  // SET_CONFIGURATION(1): open the endpoints, start the first transfers.
  // false: the controller refused an endpoint (the device stays addressed).
  virtual bool configure(DeviceController& controller) noexcept = 0;
  // SET_CONFIGURATION(0), reconfiguration or bus reset: forget every
  // transfer (the controller has dropped them or is about to).
  virtual void deconfigure() noexcept = 0;

  // SET_INTERFACE / GET_INTERFACE on one of this function's interfaces.
  virtual bool set_alternate(std::uint8_t interface, std::uint8_t alternate) noexcept {
    (void)interface;
    return alternate == 0;
  }
  virtual std::uint8_t alternate(std::uint8_t interface) const noexcept {
    (void)interface;
    return 0;
  }

  // A transfer on one of this function's endpoints completed.
  virtual void transfer_complete(EndpointAddress ep, std::size_t bytes) noexcept {
    (void)ep;
    (void)bytes;
  }
  // ENDPOINT_HALT set or cleared by the host; the active transfer on `ep` is
  // gone either way (restart it when cleared).
  virtual void halt_changed(EndpointAddress ep, bool halted) noexcept {
    (void)ep;
    (void)halted;
  }
  // Main-loop work (link processing, flash writes), outside any event.
  virtual void service() noexcept {}

 protected:
  ~UsbFunction() = default;
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_USB_FUNCTION_H_
