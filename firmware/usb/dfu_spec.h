// Constants of USB DFU 1.1 (requests, states, status codes, descriptor
// attributes).
#ifndef HADYNET_FIRMWARE_USB_DFU_SPEC_H_
#define HADYNET_FIRMWARE_USB_DFU_SPEC_H_

#include <cstdint>

namespace hadynet::usb::dfu {

inline constexpr std::uint8_t kClassApplicationSpecific = 0xFE;
inline constexpr std::uint8_t kSubclassDfu = 0x01;
inline constexpr std::uint8_t kProtocolRuntime = 0x01;
inline constexpr std::uint8_t kProtocolDfuMode = 0x02;
inline constexpr std::uint16_t kVersionBcd = 0x0110;

// Requests (DFU 1.1 table 3.2).
inline constexpr std::uint8_t kDetach = 0;
inline constexpr std::uint8_t kDnload = 1;
inline constexpr std::uint8_t kUpload = 2;
inline constexpr std::uint8_t kGetStatus = 3;
inline constexpr std::uint8_t kClrStatus = 4;
inline constexpr std::uint8_t kGetState = 5;
inline constexpr std::uint8_t kAbort = 6;
inline constexpr std::uint16_t kStatusSize = 6;  // GETSTATUS reply bytes

// bmAttributes of the functional descriptor.
inline constexpr std::uint8_t kCanDownload = 1u << 0;
inline constexpr std::uint8_t kCanUpload = 1u << 1;
inline constexpr std::uint8_t kManifestationTolerant = 1u << 2;
inline constexpr std::uint8_t kWillDetach = 1u << 3;

enum class State : std::uint8_t {
  kAppIdle = 0,
  kAppDetach = 1,
  kIdle = 2,
  kDnloadSync = 3,
  kDnBusy = 4,
  kDnloadIdle = 5,
  kManifestSync = 6,
  kManifest = 7,
  kManifestWaitReset = 8,  // never entered: the device is manifestation tolerant
  kUploadIdle = 9,
  kError = 10,
};

enum class Status : std::uint8_t {
  kOk = 0x00,
  kErrTarget = 0x01,
  kErrFile = 0x02,
  kErrWrite = 0x03,
  kErrErase = 0x04,
  kErrCheckErased = 0x05,
  kErrProg = 0x06,
  kErrVerify = 0x07,
  kErrAddress = 0x08,
  kErrNotDone = 0x09,
  kErrFirmware = 0x0A,
  kErrVendor = 0x0B,
  kErrUsbReset = 0x0C,
  kErrPowerOnReset = 0x0D,
  kErrUnknown = 0x0E,
  kErrStalledPacket = 0x0F,
};

}  // namespace hadynet::usb::dfu

#endif  // HADYNET_FIRMWARE_USB_DFU_SPEC_H_
