// The HADYNET composite USB device: CDC-ACM (the link), HID telemetry, DFU
// runtime (firmware via the ROM bootloader) and DFU mode (model slots),
// assembled over UsbDevice and one DeviceController. Everything is a member,
// sized at compile time; the board passes its controller, the MCU's 96-bit
// unique ID (serial number string) and the detach hook, the application its
// model slots (ModelSlots and their flash; none on a board without model
// flash), booted before the device is built: the configuration's name says
// which model runs (running_model.h).
//
//   HadynetUsbDevice<M, E> usb(controller, endpoint, {&slots, &flash}, hook, uid, "0.1.0");
//   usb.start();                              // controller up, pull-up on
//   loop: controller events -> usb.device().handle(event) (via the seam)
//         usb.service();                      // link bytes, flash work
//         each period: usb.publish(record);   // HID telemetry
#ifndef HADYNET_FIRMWARE_USB_HADYNET_USB_DEVICE_H_
#define HADYNET_FIRMWARE_USB_HADYNET_USB_DEVICE_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/app/period_record.h"
#include "firmware/core/model_contract.h"
#include "firmware/model_update/model_slots.h"
#include "firmware/usb/cdc_acm.h"
#include "firmware/usb/composite_descriptors.h"
#include "firmware/usb/device_controller.h"
#include "firmware/usb/dfu_mode.h"
#include "firmware/usb/dfu_runtime.h"
#include "firmware/usb/hid_telemetry.h"
#include "firmware/usb/running_model.h"
#include "firmware/usb/usb_device.h"
#include "firmware/usb/usb_identity.h"

namespace hadynet::usb {

inline constexpr std::size_t kUniqueIdBytes = 12;  // STM32 96-bit unique device ID

// "0123...": `bytes` as upper-case hex into `out` (2 chars per byte + NUL).
inline void hex_string(std::span<const std::uint8_t> bytes, std::span<char> out) noexcept {
  constexpr char kDigits[] = "0123456789ABCDEF";
  std::size_t n = 0;
  for (const std::uint8_t b : bytes) {
    if (n + 2 >= out.size()) break;
    out[n++] = kDigits[b >> 4];
    out[n++] = kDigits[b & 0x0F];
  }
  if (!out.empty()) out[n < out.size() ? n : out.size() - 1] = '\0';
}

template <firmware::GeneratedModel M, ByteEndpoint E, std::size_t kMaxReply>
class HadynetUsbDevice {
 public:
  using Cdc = CdcAcm<E, kMaxReply>;
  using Hid = HidTelemetry<M>;

  // `model`: the model slots behind the DFU-mode interface (dfu_mode.h;
  // {} on a board without model flash), booted already. The controller,
  // endpoint, slots, their flash and the hook must outlive the device.
  HadynetUsbDevice(DeviceController& controller, E& endpoint, const ModelSlotsAccess& model, DetachHook& detach,
                   std::span<const std::uint8_t, kUniqueIdBytes> unique_id, const char* firmware_version,
                   const UsbIdentity& identity = kHadynetUsbIdentity) noexcept
      : cdc_(endpoint, CdcAcmLayout{composite::kCdcCommInterface, composite::kCdcNotifyIn, composite::kCdcDataOut,
                                    composite::kCdcDataIn}),
        hid_(HidTelemetryLayout{composite::kHidInterface, composite::kHidReportIn}),
        dfu_runtime_(detach, composite::kDfuRuntimeInterface),
        dfu_mode_(model, composite::kDfuModeInterface, composite::string_index::kDfuStatus),
        device_descriptor_(composite::device_descriptor(identity)),
        functions_{&cdc_, &hid_, &dfu_runtime_, &dfu_mode_},
        device_(controller, descriptors(), functions_, /*self_powered=*/true) {
    hex_string(unique_id, serial_);
    running_model_ = running_model(model.slots, M::kModelHash);
    version_string(firmware_version, running_model_, version_);
    strings_[composite::string_index::kManufacturer] = identity.manufacturer;
    strings_[composite::string_index::kProduct] = identity.product;
    strings_[composite::string_index::kVersion] = version_.c_str();
    strings_[composite::string_index::kDfuStatus] = dfu_mode_.status_text();
  }

  HadynetUsbDevice(const HadynetUsbDevice&) = delete;
  HadynetUsbDevice& operator=(const HadynetUsbDevice&) = delete;

  void start() noexcept { device_.start(); }
  void service() noexcept { device_.service(); }
  // Each period: the loop's record (PeriodLoop::latest() after end_period()).
  void publish(const app::PeriodRecord<M>& record) noexcept { hid_.publish(record); }

  UsbDevice& device() noexcept { return device_; }
  const UsbDevice& device() const noexcept { return device_; }
  const Cdc& cdc() const noexcept { return cdc_; }
  const Hid& hid() const noexcept { return hid_; }
  const DfuRuntime& dfu_runtime() const noexcept { return dfu_runtime_; }
  const DfuMode& dfu_mode() const noexcept { return dfu_mode_; }
  const char* serial_number() const noexcept { return serial_; }
  const char* version() const noexcept { return version_.c_str(); }
  // The model the firmware runs (what the configuration's name says).
  const RunningModel& running() const noexcept { return running_model_; }

 private:
  DescriptorSet descriptors() const noexcept {
    return {device_descriptor_, composite::kConfiguration, strings_};
  }

  Cdc cdc_;
  Hid hid_;
  DfuRuntime dfu_runtime_;
  DfuMode dfu_mode_;
  std::array<std::uint8_t, 18> device_descriptor_;
  char serial_[2 * kUniqueIdBytes + 1] = {};
  RunningModel running_model_{};
  app::Text<kMaxVersionStringChars> version_;
  std::array<const char*, composite::string_index::kCount> strings_ = {
      nullptr,                                    // 0: LANGID list
      nullptr,                                    // manufacturer (identity)
      nullptr,                                    // product (identity)
      serial_,                                    // serial number
      "HADYNET link (CDC-ACM)",                   //
      "HADYNET link data",                        //
      "HADYNET telemetry (HID)",                  //
      "HADYNET firmware update (DFU detach to ROM DfuSe)",
      "HADYNET model update (signed image)",      // DFU mode alt 0
      "HADYNET model in use, read only",          // DFU mode alt 1
      nullptr,                                    // iConfiguration: version_
      nullptr,                                    // DFU status text: dfu_mode_.status_text()
  };
  std::array<UsbFunction*, 4> functions_;
  UsbDevice device_;
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_HADYNET_USB_DEVICE_H_
