// The composite device's descriptors (docs/usb.md, "Descriptors"): the
// interface and endpoint plan within the STM32F405 OTG FS's four endpoints
// (EP0 + 3), string indices, and the configuration descriptor built at
// compile time.
//
//   interface 0  CDC-ACM communication  EP 0x81 interrupt IN (16 B)   } IAD 0..1
//   interface 1  CDC data               EP 0x02 bulk OUT, 0x82 bulk IN (64 B) }
//   interface 2  HID telemetry          EP 0x83 interrupt IN (64 B, 10 ms)
//   interface 3  DFU runtime            (EP0 only)
//   interface 4  DFU mode, alt 0 / 1    (EP0 only): model update / running model (read only)
#ifndef HADYNET_FIRMWARE_USB_COMPOSITE_DESCRIPTORS_H_
#define HADYNET_FIRMWARE_USB_COMPOSITE_DESCRIPTORS_H_

#include <array>
#include <cstddef>
#include <cstdint>

#include "firmware/usb/cdc_acm.h"
#include "firmware/usb/dfu_mode.h"
#include "firmware/usb/dfu_runtime.h"
#include "firmware/usb/dfu_spec.h"
#include "firmware/usb/hid_telemetry.h"
#include "firmware/usb/usb_identity.h"
#include "firmware/usb/usb_spec.h"

namespace hadynet::usb::composite {

inline constexpr std::uint8_t kCdcCommInterface = 0;
inline constexpr std::uint8_t kCdcDataInterface = 1;
inline constexpr std::uint8_t kHidInterface = 2;
inline constexpr std::uint8_t kDfuRuntimeInterface = 3;
inline constexpr std::uint8_t kDfuModeInterface = 4;
inline constexpr std::uint8_t kInterfaceCount = 5;

inline constexpr EndpointAddress kCdcNotifyIn = 0x81;
inline constexpr EndpointAddress kCdcDataOut = 0x02;
inline constexpr EndpointAddress kCdcDataIn = 0x82;
inline constexpr EndpointAddress kHidReportIn = 0x83;
inline constexpr std::uint8_t kCdcNotifyIntervalMs = 16;

namespace string_index {
inline constexpr std::uint8_t kManufacturer = 1;
inline constexpr std::uint8_t kProduct = 2;
inline constexpr std::uint8_t kSerial = 3;
inline constexpr std::uint8_t kCdc = 4;
inline constexpr std::uint8_t kCdcData = 5;
inline constexpr std::uint8_t kHid = 6;
inline constexpr std::uint8_t kDfuRuntime = 7;
inline constexpr std::uint8_t kDfuModelUpdate = 8;   // DFU mode alt 0
inline constexpr std::uint8_t kDfuRunningModel = 9;  // DFU mode alt 1
inline constexpr std::uint8_t kVersion = 10;  // iConfiguration: firmware version and the running model (running_model.h)
inline constexpr std::uint8_t kDfuStatus = 11;  // DFU mode GETSTATUS iString: the status description (dfu_mode.h)
inline constexpr std::uint8_t kCount = 12;    // table size (index 0 is the LANGID list)
}  // namespace string_index

inline constexpr std::uint8_t kConfigAttributes = 0xC0;  // bus-powered bit 7 (always 1) + self-powered
inline constexpr std::uint8_t kMaxPower2mA = 50;         // 100 mA
inline constexpr std::uint8_t kDfuModeAttributes =
    dfu::kCanDownload | dfu::kCanUpload | dfu::kManifestationTolerant;
inline constexpr std::uint8_t kDfuRuntimeAttributes = dfu::kCanDownload | dfu::kCanUpload | dfu::kWillDetach;

// A byte array filled at compile time.
struct DescriptorBytes {
  std::array<std::uint8_t, 256> bytes{};
  std::size_t size = 0;
  constexpr void u8(unsigned v) noexcept { bytes[size++] = static_cast<std::uint8_t>(v); }
  constexpr void u16(unsigned v) noexcept {
    u8(v & 0xFF);
    u8((v >> 8) & 0xFF);
  }
  constexpr void interface(std::uint8_t number, std::uint8_t alt, std::uint8_t endpoints, std::uint8_t cls,
                           std::uint8_t sub, std::uint8_t proto, std::uint8_t name) noexcept {
    u8(9), u8(descriptor::kInterface), u8(number), u8(alt), u8(endpoints), u8(cls), u8(sub), u8(proto), u8(name);
  }
  constexpr void endpoint(EndpointAddress address, EndpointType type, std::uint16_t max_packet,
                          std::uint8_t interval) noexcept {
    u8(7), u8(descriptor::kEndpoint), u8(address), u8(static_cast<std::uint8_t>(type)), u16(max_packet), u8(interval);
  }
  constexpr void dfu_functional(std::uint8_t attributes, std::uint16_t transfer_size) noexcept {
    u8(9), u8(descriptor::kDfuFunctional), u8(attributes), u16(kDfuDetachTimeoutMs), u16(transfer_size),
        u16(dfu::kVersionBcd);
  }
};

constexpr DescriptorBytes build_configuration() noexcept {
  DescriptorBytes d;
  // Configuration header; wTotalLength patched at the end.
  d.u8(9), d.u8(descriptor::kConfiguration), d.u16(0), d.u8(kInterfaceCount), d.u8(1),
      d.u8(string_index::kVersion), d.u8(kConfigAttributes), d.u8(kMaxPower2mA);
  // CDC-ACM: IAD over interfaces 0..1.
  d.u8(8), d.u8(descriptor::kInterfaceAssociation), d.u8(kCdcCommInterface), d.u8(2), d.u8(cdc::kClassComm),
      d.u8(cdc::kSubclassAcm), d.u8(cdc::kProtocolNone), d.u8(string_index::kCdc);
  d.interface(kCdcCommInterface, 0, 1, cdc::kClassComm, cdc::kSubclassAcm, cdc::kProtocolNone, string_index::kCdc);
  d.u8(5), d.u8(descriptor::kCsInterface), d.u8(0x00), d.u16(0x0110);                        // Header, CDC 1.10
  d.u8(5), d.u8(descriptor::kCsInterface), d.u8(0x01), d.u8(0x00), d.u8(kCdcDataInterface);  // Call management
  d.u8(4), d.u8(descriptor::kCsInterface), d.u8(0x02), d.u8(0x06);  // ACM: line coding/state, SEND_BREAK
  d.u8(5), d.u8(descriptor::kCsInterface), d.u8(0x06), d.u8(kCdcCommInterface), d.u8(kCdcDataInterface);  // Union
  d.endpoint(kCdcNotifyIn, EndpointType::kInterrupt, cdc::kNotifyMaxPacket, kCdcNotifyIntervalMs);
  d.interface(kCdcDataInterface, 0, 2, cdc::kClassData, 0, 0, string_index::kCdcData);
  d.endpoint(kCdcDataOut, EndpointType::kBulk, cdc::kDataMaxPacket, 0);
  d.endpoint(kCdcDataIn, EndpointType::kBulk, cdc::kDataMaxPacket, 0);
  // HID telemetry.
  d.interface(kHidInterface, 0, 1, hid::kClassHid, 0, 0, string_index::kHid);
  for (const std::uint8_t b : hid::kHidDescriptor) d.u8(b);
  d.endpoint(kHidReportIn, EndpointType::kInterrupt, 64, hid::kPollIntervalMs);
  // DFU runtime (firmware through the ROM bootloader).
  d.interface(kDfuRuntimeInterface, 0, 0, dfu::kClassApplicationSpecific, dfu::kSubclassDfu, dfu::kProtocolRuntime,
              string_index::kDfuRuntime);
  d.dfu_functional(kDfuRuntimeAttributes, kDfuTransferSize);
  // DFU mode (model images), one functional descriptor after each alternate.
  static_assert(kDfuAlternateCount == 2 && kDfuAltModelUpdate == 0 && kDfuAltRunningModel == 1);
  d.interface(kDfuModeInterface, kDfuAltModelUpdate, 0, dfu::kClassApplicationSpecific, dfu::kSubclassDfu,
              dfu::kProtocolDfuMode, string_index::kDfuModelUpdate);
  d.dfu_functional(kDfuModeAttributes, kDfuTransferSize);
  d.interface(kDfuModeInterface, kDfuAltRunningModel, 0, dfu::kClassApplicationSpecific, dfu::kSubclassDfu,
              dfu::kProtocolDfuMode, string_index::kDfuRunningModel);
  d.dfu_functional(kDfuModeAttributes, kDfuTransferSize);
  d.bytes[2] = static_cast<std::uint8_t>(d.size & 0xFF);
  d.bytes[3] = static_cast<std::uint8_t>(d.size >> 8);
  return d;
}

inline constexpr std::size_t kConfigurationSize = build_configuration().size;

constexpr std::array<std::uint8_t, kConfigurationSize> configuration_descriptor() noexcept {
  const DescriptorBytes d = build_configuration();
  std::array<std::uint8_t, kConfigurationSize> out{};
  for (std::size_t i = 0; i < kConfigurationSize; ++i) out[i] = d.bytes[i];
  return out;
}

inline constexpr std::array<std::uint8_t, kConfigurationSize> kConfiguration = configuration_descriptor();
static_assert(kConfigurationSize <= kControlBufferSize, "the configuration must fit the control buffer");

constexpr std::array<std::uint8_t, 18> device_descriptor(const UsbIdentity& id) noexcept {
  return {18,
          descriptor::kDevice,
          0x00, 0x02,        // bcdUSB 2.00
          0xEF, 0x02, 0x01,  // Miscellaneous / Common / Interface Association (composite with IADs)
          static_cast<std::uint8_t>(kEp0MaxPacket),
          static_cast<std::uint8_t>(id.vendor_id), static_cast<std::uint8_t>(id.vendor_id >> 8),
          static_cast<std::uint8_t>(id.product_id), static_cast<std::uint8_t>(id.product_id >> 8),
          static_cast<std::uint8_t>(id.device_release_bcd), static_cast<std::uint8_t>(id.device_release_bcd >> 8),
          string_index::kManufacturer,
          string_index::kProduct,
          string_index::kSerial,
          1};
}

}  // namespace hadynet::usb::composite

#endif  // HADYNET_FIRMWARE_USB_COMPOSITE_DESCRIPTORS_H_
