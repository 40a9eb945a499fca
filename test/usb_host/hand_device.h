// The hand's composite USB device (HadynetUsbDevice: CDC-ACM link, HID
// telemetry, DFU runtime, DFU mode) as an EmulatedDevice for the testbed
// (usb_testbed.h): the firmware's stack over the host backend
// FakeController, with a link::DeviceLink on a HadynetRuntime behind the
// CDC function, the F405 flash simulated (SimulatedNorFlash) behind DFU
// mode, and a DetachHook that records DFU_DETACH.
//
// Like every EmulatedDevice, call its methods under the bus lock
// (UsbTestbed::locked), except in the constructor.
#ifndef HADYNET_TEST_USB_HOST_HAND_DEVICE_H_
#define HADYNET_TEST_USB_HOST_HAND_DEVICE_H_

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "firmware/app/period_record.h"
#include "hadynet_model_q15.h"
#include "test/usb_host/emulated_device.h"

namespace hadynet::usb::host_testing {

using Q = model_q15::Model;

// The MCU unique ID the hand reports (bytes as a board reads them) and its
// serial-number string.
inline constexpr std::array<std::uint8_t, 12> kFixtureUid = {0x20, 0x00, 0x3B, 0x00, 0x11, 0x51,
                                                             0x32, 0x30, 0x36, 0x39, 0x34, 0x38};
inline constexpr const char* kFixtureSerial = "20003B001151323036393438";
inline constexpr const char* kFixtureFirmwareVersion = "0.1.0-umockdev";

class HandDevice final : public EmulatedDevice {
 public:
  // Started (controller initialised, pull-up on): ready to plug.
  HandDevice();
  ~HandDevice() override;

  host::FakeController& controller() noexcept override;
  void service() noexcept override;
  bool attached() const noexcept override { return attached_; }

  // HID telemetry: HadynetUsbDevice::publish.
  void publish(const app::PeriodRecord<Q>& record);
  std::string serial_number() const;
  std::string version_string() const;  // "fw <version> model <hash>"

  // DFU_DETACH: acknowledged by the stack, then the board hook runs (after
  // the status stage). The hand records it, calls `on_detach` (under the bus
  // lock: no testbed calls in it) and, with set_leave_on_detach(true),
  // leaves the bus as the real board's reset into the ROM bootloader does
  // (attached() false: the testbed unplugs it and calls its on_left).
  int detach_requests() const noexcept { return detach_requests_; }
  std::uint16_t last_detach_timeout_ms() const noexcept { return last_detach_timeout_ms_; }
  void set_leave_on_detach(bool leave) noexcept { leave_on_detach_ = leave; }
  void set_on_detach(std::function<void(std::uint16_t timeout_ms)> on_detach) { on_detach_ = std::move(on_detach); }

  struct Parts;  // the runtime, link, flash and stack (hand_device.cc)

 private:
  void detached(std::uint16_t timeout_ms) noexcept;

  std::unique_ptr<Parts> parts_;
  bool attached_ = true;
  bool leave_on_detach_ = false;
  int detach_requests_ = 0;
  std::uint16_t last_detach_timeout_ms_ = 0;
  std::function<void(std::uint16_t)> on_detach_;
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_HAND_DEVICE_H_
