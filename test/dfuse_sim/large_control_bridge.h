// Serves the control transfers whose data stage is larger than the device
// stack's control buffer (kControlBufferSize, 256 bytes) for one function:
// the ROM DfuSe bootloader moves wTransferSize = 2048 bytes per DNLOAD and
// UPLOAD, which UsbDevice (firmware/usb/usb_device.h) would STALL.
//
// It sits between UsbDevice and the host backend: UsbDevice drives it as its
// DeviceController (every call is passed on unchanged), and the controller
// delivers its events to it. A SETUP that `function` must serve with a data
// stage over 256 bytes (a class request to `interface` of a configured
// device, wLength > kControlBufferSize) is taken here: the function answers
// through the same UsbFunction calls as from UsbDevice (control_setup with a
// 2048-byte buffer, control_out, control_complete), and this class moves the
// packets (64 bytes, ZLP after a full last packet shorter than wLength,
// status stage). Every other event goes to UsbDevice. A test-only adapter:
// the firmware's stack is not changed.
#ifndef HADYNET_TEST_DFUSE_SIM_LARGE_CONTROL_BRIDGE_H_
#define HADYNET_TEST_DFUSE_SIM_LARGE_CONTROL_BRIDGE_H_

#include <array>
#include <cstddef>
#include <cstdint>

#include "firmware/usb/device_controller.h"
#include "firmware/usb/usb_device.h"
#include "firmware/usb/usb_function.h"

namespace hadynet::usb::host_testing {

class LargeControlBridge final : public DeviceController, public ControllerEventHandler {
 public:
  static constexpr std::size_t kMaxDataStage = 2048;  // bytes: the DfuSe wTransferSize

  LargeControlBridge(DeviceController& controller, UsbFunction& function, std::uint8_t interface) noexcept
      : controller_(controller), function_(function), interface_(interface) {}
  // The stack whose events this forwards (its state decides whether class
  // requests are served at all). Set before UsbDevice::start().
  void attach(UsbDevice& device) noexcept { device_ = &device; }

  // ---- DeviceController: passed on ----
  void init(ControllerEventHandler& handler) noexcept override;
  void set_connected(bool connected) noexcept override { controller_.set_connected(connected); }
  void set_address(std::uint8_t address) noexcept override { controller_.set_address(address); }
  bool open_endpoint(const EndpointConfig& config) noexcept override { return controller_.open_endpoint(config); }
  void close_endpoint(EndpointAddress ep) noexcept override { controller_.close_endpoint(ep); }
  bool start_transfer(EndpointAddress ep, std::span<std::uint8_t> buffer) noexcept override {
    return controller_.start_transfer(ep, buffer);
  }
  void stall_control() noexcept override { controller_.stall_control(); }
  void set_endpoint_halt(EndpointAddress ep, bool halted) noexcept override {
    controller_.set_endpoint_halt(ep, halted);
  }

  // ---- ControllerEventHandler ----
  void handle(const ControllerEvent& event) noexcept override;

  // Control transfers served here (tests).
  std::size_t transfers() const noexcept { return transfers_; }

 private:
  enum class Stage : std::uint8_t { kNone, kDataIn, kDataOut, kStatusIn, kStatusOut };
  bool takes(const SetupPacket& s) const noexcept;
  void begin(const SetupPacket& s) noexcept;
  void in_complete() noexcept;
  void out_complete(std::size_t bytes) noexcept;
  void send_packet() noexcept;
  void arm_out() noexcept;
  void fail() noexcept;

  DeviceController& controller_;
  UsbFunction& function_;
  std::uint8_t interface_;
  UsbDevice* device_ = nullptr;
  ControllerEventHandler* stack_ = nullptr;

  Stage stage_ = Stage::kNone;
  SetupPacket setup_{};
  std::size_t size_ = 0;    // bytes of the data stage
  std::size_t done_ = 0;    // bytes moved
  std::size_t packet_ = 0;  // bytes of the packet in flight
  std::size_t transfers_ = 0;
  std::array<std::uint8_t, kMaxDataStage> buffer_{};
  std::array<std::uint8_t, kEp0MaxPacket> status_{};
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_DFUSE_SIM_LARGE_CONTROL_BRIDGE_H_
