// The hand's composite USB device (HadynetUsbDevice: CDC-ACM link, HID
// telemetry, DFU runtime, DFU mode) as an EmulatedDevice for the testbed
// (usb_testbed.h): the firmware's stack over the host backend
// FakeController, with a link::DeviceLink on a HadynetRuntime behind the
// CDC function, a DetachHook that records DFU_DETACH, and the model slots
// as the firmware has them: a ModelSlots for the build's q15 model, trusting
// the development key (keys/development.key.pub), over a simulated F405
// flash, booted with the app's boot rule and self-test (model_store.h)
// before the USB device is built. A new HandDevice over another's flash
// cells is that hand after a power-on.
//
// The flash has the F405's sector table but its worst-case times scaled to
// 1 % (8/24/40 ms erases) and 1 us per programmed byte: the DFU clients
// really sleep every bwPollTimeout, and at the datasheet's figures one
// 173 KB image asks for 8 s of erase and 4.3 s of programming waits. The
// exact F405 poll times are test/usb's (dfu_test.cc).
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
#include <vector>

#include "firmware/app/period_record.h"
#include "firmware/model_update/slot_status.h"
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
  // Started (controller initialised, pull-up on): ready to plug. `cells`:
  // the flash at power-on (another hand's flash_cells()); null: erased.
  // `model_slots` false: a board without model flash (no ModelSlots; the
  // DFU model interface refuses images).
  explicit HandDevice(const std::vector<std::uint8_t>* cells = nullptr, bool model_slots = true);
  ~HandDevice() override;

  host::FakeController& controller() noexcept override;
  void service() noexcept override;
  bool attached() const noexcept override { return attached_; }

  // HID telemetry: HadynetUsbDevice::publish.
  void publish(const app::PeriodRecord<Q>& record);
  std::string serial_number() const;
  std::string version_string() const;  // "fw <version> model <hash> (<source>)"
  // The model slots (with model_slots): what the boot rule chose, each slot's status.
  model_update::BootChoice boot_choice() const;
  model_update::SlotStatus slot_status(model_update::SlotId slot) const;
  // A copy of the flash cells (for a power-on of another HandDevice).
  std::vector<std::uint8_t> flash_cells() const;

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
