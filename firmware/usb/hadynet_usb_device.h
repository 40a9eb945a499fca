// The HADYNET composite USB device: CDC-ACM (the link), HID telemetry, DFU
// runtime (firmware via the ROM bootloader) and DFU mode (model slots),
// assembled over UsbDevice and one DeviceController. Everything is a member,
// sized at compile time; the board passes its controller, the MCU's 96-bit
// unique ID (serial number string), the flash, the model-slot targets and
// the detach hook.
//
//   HadynetUsbDevice<M, E> usb(controller, endpoint, flash, targets, hook, uid, "0.1.0");
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
#include "firmware/flash/flash_device.h"
#include "firmware/usb/cdc_acm.h"
#include "firmware/usb/composite_descriptors.h"
#include "firmware/usb/device_controller.h"
#include "firmware/usb/dfu_mode.h"
#include "firmware/usb/dfu_runtime.h"
#include "firmware/usb/hid_telemetry.h"
#include "firmware/usb/usb_device.h"
#include "firmware/usb/usb_identity.h"

namespace hadynet::usb {

inline constexpr std::size_t kUniqueIdBytes = 12;  // STM32 96-bit unique device ID
inline constexpr std::size_t kMaxFirmwareVersionChars = 24;

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

// "fw <version> model <hash, 16 hex digits>" (the configuration's name).
inline void version_string(const char* firmware_version, std::uint64_t model_hash, std::span<char> out) noexcept {
  std::size_t n = 0;
  const auto put = [&](char c) {
    if (n + 1 < out.size()) out[n++] = c;
  };
  for (const char* p = "fw "; *p != '\0'; ++p) put(*p);
  for (std::size_t i = 0; firmware_version != nullptr && firmware_version[i] != '\0' && i < kMaxFirmwareVersionChars;
       ++i) {
    put(firmware_version[i]);
  }
  for (const char* p = " model "; *p != '\0'; ++p) put(*p);
  constexpr char kDigits[] = "0123456789abcdef";
  for (int shift = 60; shift >= 0; shift -= 4) put(kDigits[(model_hash >> shift) & 0xF]);
  if (!out.empty()) out[n] = '\0';
}

template <firmware::GeneratedModel M, ByteEndpoint E, std::size_t kMaxReply>
class HadynetUsbDevice {
 public:
  using Cdc = CdcAcm<E, kMaxReply>;
  using Hid = HidTelemetry<M>;

  // `targets`: the DFU-mode alternates (composite::kDfuAlternates of them:
  // alt 0 the inactive model slot, alt 1 the active one, read only). The
  // controller, endpoint, flash, targets and hook must outlive the device.
  HadynetUsbDevice(DeviceController& controller, E& endpoint, flash::FlashDevice& flash,
                   std::span<const DfuTarget, composite::kDfuAlternates> targets, DetachHook& detach,
                   std::span<const std::uint8_t, kUniqueIdBytes> unique_id, const char* firmware_version,
                   const UsbIdentity& identity = kHadynetUsbIdentity) noexcept
      : cdc_(endpoint, CdcAcmLayout{composite::kCdcCommInterface, composite::kCdcNotifyIn, composite::kCdcDataOut,
                                    composite::kCdcDataIn}),
        hid_(HidTelemetryLayout{composite::kHidInterface, composite::kHidReportIn}),
        dfu_runtime_(detach, composite::kDfuRuntimeInterface),
        dfu_mode_(flash, targets, composite::kDfuModeInterface),
        device_descriptor_(composite::device_descriptor(identity)),
        functions_{&cdc_, &hid_, &dfu_runtime_, &dfu_mode_},
        device_(controller, descriptors(), functions_, /*self_powered=*/true) {
    hex_string(unique_id, serial_);
    version_string(firmware_version, M::kModelHash, version_);
    strings_[composite::string_index::kManufacturer] = identity.manufacturer;
    strings_[composite::string_index::kProduct] = identity.product;
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
  const char* version() const noexcept { return version_; }

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
  char version_[3 + kMaxFirmwareVersionChars + 7 + 16 + 1] = {};
  std::array<const char*, composite::string_index::kCount> strings_ = {
      nullptr,                                    // 0: LANGID list
      nullptr,                                    // manufacturer (identity)
      nullptr,                                    // product (identity)
      serial_,                                    // serial number
      "HADYNET link (CDC-ACM)",                   //
      "HADYNET link data",                        //
      "HADYNET telemetry (HID)",                  //
      "HADYNET firmware update (DFU detach to ROM DfuSe)",
      "HADYNET model slot (inactive)",            //
      "HADYNET model slot (active, read only)",   //
      version_,                                   // iConfiguration
  };
  std::array<UsbFunction*, 4> functions_;
  UsbDevice device_;
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_HADYNET_USB_DEVICE_H_
