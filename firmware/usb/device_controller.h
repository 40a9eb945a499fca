// ============================================================================
//  THE DEVICE-CONTROLLER SEAM: everything the portable USB stack needs from a
//  USB device controller, and everything it hears from one.
//
//  Backends: the STM32F405 OTG FS register driver
//  (boards/stm32f405/otg_fs_controller.h) and the
//  host fake (firmware/usb/host/fake_controller.h) that tests, the fuzzer and
//  a umockdev fixture drive. The stack above the seam is portable.
//
//  Contract (docs/usb.md, "The seam"):
//   * Full speed only. EP0 max packet 64. The stack uses endpoint numbers
//     0..3 (OTG FS on the F405: 4 bidirectional endpoints incl. EP0).
//   * One context: the controller delivers events by calling
//     ControllerEventHandler::handle() from the same thread that calls
//     UsbDevice::service() (e.g. its interrupt queues events and a poll()
//     in the main loop hands them over). The stack is not reentrant; it never
//     calls back into the controller from inside a controller call other than
//     from handle().
//   * start_transfer(ep, buffer): the buffer stays owned by the stack and
//     valid until that endpoint's kTransferComplete, a bus reset or
//     close_endpoint(); at most one transfer per endpoint address is active.
//       IN:  sends buffer.size() bytes as max-packet-sized packets, the last
//            one short; size 0 sends one zero-length packet. No automatic
//            zero-length packet after a full last packet: the stack sends one
//            itself when the protocol needs it. Complete when the host has
//            acknowledged the last packet; bytes = buffer.size().
//       OUT: receives packets into buffer until a short packet arrives or the
//            buffer is full (then bytes = bytes received). buffer.size() is a
//            multiple of the max packet size, or 0..64 on EP0.
//     The stack starts EP0 transfers one packet at a time (<= 64 bytes).
//   * kSetup: the 8 bytes of a SETUP packet on EP0. A SETUP cancels whatever
//     EP0 transfer was active in either direction (no completion is reported
//     for it) and clears an EP0 stall; the stack then starts the data or
//     status stage.
//   * stall_control(): protocol stall of the current control transfer: both
//     EP0 directions answer STALL until the next SETUP.
//   * set_endpoint_halt(ep, true/false) for endpoints 1..3 (ENDPOINT_HALT):
//     halted endpoints answer STALL; clearing the halt resets the data toggle
//     to DATA0 and leaves the endpoint idle (any active transfer is dropped).
//   * set_address(a) is called when a SET_ADDRESS request has been accepted,
//     BEFORE the stack starts its status stage (a zero-length IN on address
//     0). The controller must answer that status stage on the old address and
//     use the new one from the next transaction on. OTG FS: write DCFG.DAD
//     immediately (the core itself finishes the status stage on address 0, as
//     its reference manual requires DAD before the status stage). A
//     controller whose address register applies at once must hold the value
//     and write it when the EP0 IN status packet completes.
//   * open_endpoint(config) for endpoints 1..3 at SET_CONFIGURATION (and
//     SET_INTERFACE); resets the data toggle; false if the controller cannot
//     (then the stack refuses the configuration). close_endpoint() cancels an
//     active transfer silently. EP0 is always open after a bus reset.
//   * kBusReset: the controller has already aborted every transfer, closed
//     endpoints 1..3 and returned to address 0; the stack forgets its state.
//   * kSuspend/kResume: bus idle for 3 ms / activity again. Informational.
// ============================================================================
#ifndef HADYNET_FIRMWARE_USB_DEVICE_CONTROLLER_H_
#define HADYNET_FIRMWARE_USB_DEVICE_CONTROLLER_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/usb/usb_spec.h"

namespace hadynet::usb {

// Highest endpoint number the stack may use (OTG FS on the F405: 0..3).
inline constexpr std::uint8_t kMaxEndpointNumber = 3;

struct EndpointConfig {
  EndpointAddress address = 0;               // 0x01..0x03 or 0x81..0x83
  EndpointType type = EndpointType::kBulk;  // bulk or interrupt (the stack uses no isochronous)
  std::uint16_t max_packet = 64;            // bytes, <= 64 at full speed for bulk/interrupt
};

struct ControllerEvent {
  enum class Type : std::uint8_t { kBusReset, kSetup, kTransferComplete, kSuspend, kResume };
  Type type = Type::kBusReset;
  EndpointAddress endpoint = 0;                          // kTransferComplete: which endpoint
  std::uint16_t bytes = 0;                               // kTransferComplete: bytes moved
  std::array<std::uint8_t, kSetupPacketSize> setup{};  // kSetup: the packet as received

  static ControllerEvent bus_reset() noexcept { return {}; }
  static ControllerEvent setup_packet(std::span<const std::uint8_t, kSetupPacketSize> bytes) noexcept {
    ControllerEvent e;
    e.type = Type::kSetup;
    for (std::size_t i = 0; i < kSetupPacketSize; ++i) e.setup[i] = bytes[i];
    return e;
  }
  static ControllerEvent transfer_complete(EndpointAddress ep, std::uint16_t n) noexcept {
    ControllerEvent e;
    e.type = Type::kTransferComplete;
    e.endpoint = ep;
    e.bytes = n;
    return e;
  }
  static ControllerEvent suspend() noexcept {
    ControllerEvent e;
    e.type = Type::kSuspend;
    return e;
  }
  static ControllerEvent resume() noexcept {
    ControllerEvent e;
    e.type = Type::kResume;
    return e;
  }
};

// What the controller calls with each event (the UsbDevice).
class ControllerEventHandler {
 public:
  virtual void handle(const ControllerEvent& event) noexcept = 0;

 protected:
  ~ControllerEventHandler() = default;
};

// The controller, as the stack drives it.
class DeviceController {
 public:
  // Core and PHY up, FIFOs allocated, EP0 ready, the pull-up OFF. Events go
  // to `handler` from now on.
  virtual void init(ControllerEventHandler& handler) noexcept = 0;
  // D+ pull-up on (the host sees the device) or off.
  virtual void set_connected(bool connected) noexcept = 0;
  virtual void set_address(std::uint8_t address) noexcept = 0;
  virtual bool open_endpoint(const EndpointConfig& config) noexcept = 0;
  virtual void close_endpoint(EndpointAddress ep) noexcept = 0;
  // false if the endpoint is not open, halted, or already busy.
  virtual bool start_transfer(EndpointAddress ep, std::span<std::uint8_t> buffer) noexcept = 0;
  virtual void stall_control() noexcept = 0;
  virtual void set_endpoint_halt(EndpointAddress ep, bool halted) noexcept = 0;

 protected:
  ~DeviceController() = default;
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_DEVICE_CONTROLLER_H_
