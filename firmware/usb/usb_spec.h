// Constants of the USB 2.0 specification (chapter 9) that the device stack
// uses, the 8-byte SETUP packet, and little-endian field access. Pure data:
// no I/O, no heap; builds for the host and the Cortex-M4.
#ifndef HADYNET_FIRMWARE_USB_USB_SPEC_H_
#define HADYNET_FIRMWARE_USB_USB_SPEC_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/core/little_endian.h"

namespace hadynet::usb {

// Endpoint address: bit 7 the direction (1 = IN, device to host), bits 0..3
// the endpoint number.
using EndpointAddress = std::uint8_t;
inline constexpr EndpointAddress kDirIn = 0x80;
constexpr std::uint8_t endpoint_number(EndpointAddress ep) noexcept { return ep & 0x0F; }
constexpr bool is_in(EndpointAddress ep) noexcept { return (ep & kDirIn) != 0; }
constexpr EndpointAddress in_endpoint(std::uint8_t number) noexcept {
  return static_cast<EndpointAddress>(kDirIn | number);
}
constexpr EndpointAddress out_endpoint(std::uint8_t number) noexcept { return number; }

// Full speed EP0: 64 bytes, the stack's only choice.
inline constexpr std::size_t kEp0MaxPacket = 64;

// bmRequestType fields.
inline constexpr std::uint8_t kRequestDirIn = 0x80;
enum class RequestKind : std::uint8_t { kStandard = 0, kClass = 1, kVendor = 2, kReserved = 3 };
enum class Recipient : std::uint8_t { kDevice = 0, kInterface = 1, kEndpoint = 2, kOther = 3 };

// Standard requests (USB 2.0 table 9-4).
namespace request {
inline constexpr std::uint8_t kGetStatus = 0;
inline constexpr std::uint8_t kClearFeature = 1;
inline constexpr std::uint8_t kSetFeature = 3;
inline constexpr std::uint8_t kSetAddress = 5;
inline constexpr std::uint8_t kGetDescriptor = 6;
inline constexpr std::uint8_t kSetDescriptor = 7;
inline constexpr std::uint8_t kGetConfiguration = 8;
inline constexpr std::uint8_t kSetConfiguration = 9;
inline constexpr std::uint8_t kGetInterface = 10;
inline constexpr std::uint8_t kSetInterface = 11;
inline constexpr std::uint8_t kSynchFrame = 12;
}  // namespace request

// Feature selectors (table 9-6).
inline constexpr std::uint16_t kFeatureEndpointHalt = 0;
inline constexpr std::uint16_t kFeatureRemoteWakeup = 1;
inline constexpr std::uint16_t kFeatureTestMode = 2;

// Descriptor types (table 9-5, plus the IAD of the ECN and class types).
namespace descriptor {
inline constexpr std::uint8_t kDevice = 1;
inline constexpr std::uint8_t kConfiguration = 2;
inline constexpr std::uint8_t kString = 3;
inline constexpr std::uint8_t kInterface = 4;
inline constexpr std::uint8_t kEndpoint = 5;
inline constexpr std::uint8_t kDeviceQualifier = 6;
inline constexpr std::uint8_t kOtherSpeedConfiguration = 7;
inline constexpr std::uint8_t kInterfaceAssociation = 11;
inline constexpr std::uint8_t kHid = 0x21;
inline constexpr std::uint8_t kHidReport = 0x22;
inline constexpr std::uint8_t kCsInterface = 0x24;  // CDC class-specific interface
inline constexpr std::uint8_t kDfuFunctional = 0x21;
}  // namespace descriptor

// Endpoint transfer types (bmAttributes bits 0..1).
enum class EndpointType : std::uint8_t { kControl = 0, kIsochronous = 1, kBulk = 2, kInterrupt = 3 };

// The SETUP packet (USB 2.0 table 9-2), fields in host byte order.
struct SetupPacket {
  std::uint8_t request_type = 0;  // bmRequestType
  std::uint8_t request = 0;       // bRequest
  std::uint16_t value = 0;        // wValue
  std::uint16_t index = 0;        // wIndex
  std::uint16_t length = 0;       // wLength: bytes of the data stage (at most)

  constexpr bool is_in() const noexcept { return (request_type & kRequestDirIn) != 0; }
  constexpr RequestKind kind() const noexcept { return static_cast<RequestKind>((request_type >> 5) & 3); }
  constexpr Recipient recipient() const noexcept { return static_cast<Recipient>(request_type & 0x1F); }
  constexpr std::uint8_t value_low() const noexcept { return static_cast<std::uint8_t>(value & 0xFF); }
  constexpr std::uint8_t value_high() const noexcept { return static_cast<std::uint8_t>(value >> 8); }
  constexpr std::uint8_t index_low() const noexcept { return static_cast<std::uint8_t>(index & 0xFF); }
};

inline constexpr std::size_t kSetupPacketSize = 8;

// The 8 wire bytes of a SETUP packet (little-endian fields).
constexpr SetupPacket parse_setup(std::span<const std::uint8_t, kSetupPacketSize> b) noexcept {
  SetupPacket s;
  s.request_type = b[0];
  s.request = b[1];
  s.value = static_cast<std::uint16_t>(b[2] | (b[3] << 8));
  s.index = static_cast<std::uint16_t>(b[4] | (b[5] << 8));
  s.length = static_cast<std::uint16_t>(b[6] | (b[7] << 8));
  return s;
}

constexpr void serialize_setup(const SetupPacket& s, std::span<std::uint8_t, kSetupPacketSize> b) noexcept {
  b[0] = s.request_type;
  b[1] = s.request;
  b[2] = static_cast<std::uint8_t>(s.value);
  b[3] = static_cast<std::uint8_t>(s.value >> 8);
  b[4] = static_cast<std::uint8_t>(s.index);
  b[5] = static_cast<std::uint8_t>(s.index >> 8);
  b[6] = static_cast<std::uint8_t>(s.length);
  b[7] = static_cast<std::uint8_t>(s.length >> 8);
}

// bmRequestType from its parts.
constexpr std::uint8_t request_type(bool in, RequestKind kind, Recipient recipient) noexcept {
  return static_cast<std::uint8_t>((in ? kRequestDirIn : 0) | (static_cast<std::uint8_t>(kind) << 5) |
                                   static_cast<std::uint8_t>(recipient));
}

// Little-endian stores and loads into byte buffers (caller checks bounds).
using firmware::get_le16;
using firmware::get_le32;
using firmware::put_le16;
using firmware::put_le32;

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_USB_SPEC_H_
