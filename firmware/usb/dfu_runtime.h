// The DFU 1.1 runtime interface (bInterfaceProtocol 1): DFU_DETACH asks the
// board to reboot into its DFU-mode bootloader (the STM32F405's ROM DfuSe
// bootloader, 0483:df11), through DetachHook, once the request's status
// stage has completed (the host has seen success). GETSTATUS and GETSTATE
// answer appIDLE (or appDETACH after a detach). bitWillDetach: the device
// goes away by itself; the host need not reset the bus.
#ifndef HADYNET_FIRMWARE_USB_DFU_RUNTIME_H_
#define HADYNET_FIRMWARE_USB_DFU_RUNTIME_H_

#include <cstdint>
#include <span>

#include "firmware/usb/dfu_spec.h"
#include "firmware/usb/usb_function.h"

namespace hadynet::usb {

// The board's half: reboot into the ROM bootloader. On the MCU it does not
// return; the host backend records the call.
class DetachHook {
 public:
  virtual void detach_to_bootloader(std::uint16_t timeout_ms) noexcept = 0;

 protected:
  ~DetachHook() = default;
};

// wDetachTimeOut (ms) in the runtime functional descriptor. Its wTransferSize
// is the model interface's (kDfuTransferSize, dfu_mode.h), not the ROM
// bootloader's: dfu-util 0.11 takes the first DFU functional descriptor of
// the configuration for every interface, so a larger value here would make
// it send blocks the model interface STALLs. The ROM bootloader reports its
// own after DFU_DETACH re-enumerates the MCU.
inline constexpr std::uint16_t kDfuDetachTimeoutMs = 1000;

class DfuRuntime final : public UsbFunction {
 public:
  DfuRuntime(DetachHook& hook, std::uint8_t interface) noexcept : hook_(hook), interface_(interface) {}

  bool owns_interface(std::uint8_t interface) const noexcept override { return interface == interface_; }
  bool owns_endpoint(EndpointAddress) const noexcept override { return false; }

  ControlReply control_setup(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept override {
    if (s.kind() != RequestKind::kClass || s.recipient() != Recipient::kInterface || s.index != interface_) {
      return ControlReply::stall();
    }
    switch (s.request) {
      case dfu::kDetach:
        if (s.is_in() || s.length != 0 || state_ != dfu::State::kAppIdle) break;
        return ControlReply::ack();  // acts in control_complete
      case dfu::kGetStatus:
        if (!s.is_in() || s.value != 0 || s.length != dfu::kStatusSize) break;
        buffer[0] = static_cast<std::uint8_t>(dfu::Status::kOk);
        buffer[1] = buffer[2] = buffer[3] = 0;  // bwPollTimeout
        buffer[4] = static_cast<std::uint8_t>(state_);
        buffer[5] = 0;
        return ControlReply::data_in(dfu::kStatusSize);
      case dfu::kGetState:
        if (!s.is_in() || s.value != 0 || s.length != 1) break;
        buffer[0] = static_cast<std::uint8_t>(state_);
        return ControlReply::data_in(1);
      default:
        break;
    }
    return ControlReply::stall();
  }

  void control_complete(const SetupPacket& s) noexcept override {
    if (s.request == dfu::kDetach && s.kind() == RequestKind::kClass) {
      state_ = dfu::State::kAppDetach;
      hook_.detach_to_bootloader(s.value);
    }
  }

  bool configure(DeviceController&) noexcept override { return true; }
  void deconfigure() noexcept override {}

  dfu::State state() const noexcept { return state_; }

 private:
  DetachHook& hook_;
  std::uint8_t interface_;
  dfu::State state_ = dfu::State::kAppIdle;
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_DFU_RUNTIME_H_
