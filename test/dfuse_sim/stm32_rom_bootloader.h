// A simulated STM32F405 ROM DfuSe bootloader (ST AN3156) as an
// EmulatedDevice: 0483:df11, bcdDevice 0x2200, one configuration, interface
// 0 (DFU mode, FE/01/02) with four alternates whose iInterface strings are
// the DfuSe memory descriptors of the real ROM, one DFU functional
// descriptor (bmAttributes 0x0B, wDetachTimeOut 255 ms, wTransferSize
// 2048 bytes, bcdDFU 0x011A), and a 1 MiB flash model behind alternate 0.
//
// Built like the firmware's devices: the firmware's UsbDevice over the host
// backend FakeController, the DFU interface (DfuseRomInterface) a
// UsbFunction. LargeControlBridge sits between the two so that 2048-byte
// DNLOAD/UPLOAD data stages get through (the stack's control buffer is 256
// bytes). Like the EmulatedDevice contract says, the device side has
// started (connected) when the constructor returns; the host enumerates.
#ifndef HADYNET_TEST_DFUSE_SIM_STM32_ROM_BOOTLOADER_H_
#define HADYNET_TEST_DFUSE_SIM_STM32_ROM_BOOTLOADER_H_

#include <cstdint>
#include <optional>

#include "firmware/usb/host/fake_controller.h"
#include "firmware/usb/usb_device.h"
#include "test/dfuse_sim/dfuse_rom_interface.h"
#include "test/dfuse_sim/large_control_bridge.h"
#include "test/dfuse_sim/rom_flash_model.h"
#include "test/usb_host/emulated_device.h"

namespace hadynet::usb::host_testing {

inline constexpr std::uint16_t kRomVendorId = 0x0483;
inline constexpr std::uint16_t kRomProductId = 0xDF11;
inline constexpr std::uint8_t kRomDfuInterface = 0;

class Stm32RomBootloader final : public EmulatedDevice {
 public:
  explicit Stm32RomBootloader(const DfuseFaults& faults = {});
  Stm32RomBootloader(const Stm32RomBootloader&) = delete;
  Stm32RomBootloader& operator=(const Stm32RomBootloader&) = delete;

  host::FakeController& controller() noexcept override { return controller_; }
  void service() noexcept override { device_.service(); }
  bool attached() const noexcept override { return !dfu_.left(); }

  // Faults take effect from the next request (the leaky cell from the next write).
  void set_faults(const DfuseFaults& faults) noexcept;

  // The reported bwPollTimeout in percent of the datasheet's worst case
  // (DfuseRomInterface::set_poll_timeout_percent; default 100).
  void set_poll_timeout_percent(std::uint32_t percent) noexcept { dfu_.set_poll_timeout_percent(percent); }

  RomFlashModel& flash() noexcept { return flash_; }
  const DfuseRomInterface& dfu() const noexcept { return dfu_; }
  const UsbDevice& device() const noexcept { return device_; }
  const LargeControlBridge& bridge() const noexcept { return bridge_; }
  // Where "leave" jumped (nullopt: it did not).
  std::optional<std::uint32_t> jump_address() const noexcept { return dfu_.jump_address(); }

 private:
  host::FakeController controller_;
  RomFlashModel flash_;
  DfuseFaults faults_;
  DfuseRomInterface dfu_;
  LargeControlBridge bridge_;
  UsbFunction* functions_[1];
  UsbDevice device_;
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_DFUSE_SIM_STM32_ROM_BOOTLOADER_H_
