// What is attached over USB (libusb-1.0): every HADYNET forearm MCU running
// the firmware (the project's VID:PID, firmware/usb/usb_identity.h) and
// every STM32 in its ROM DfuSe bootloader (0483:df11). Read-only: devices are
// opened only to read string descriptors, no interface is claimed.
#ifndef HADYNET_TOOLS_USB_USB_INVENTORY_H_
#define HADYNET_TOOLS_USB_USB_INVENTORY_H_

#include <cstdint>
#include <string>
#include <vector>

struct libusb_context;

namespace hadynet::tools::usb {

inline constexpr std::uint16_t kStmVendorId = 0x0483;
inline constexpr std::uint16_t kStmDfuProductId = 0xDF11;  // STM32 ROM bootloader in DFU mode (AN2606)

// Which functions a configuration offers (from its interface descriptors).
struct InterfacesPresent {
  bool cdc_acm = false;      // CDC comm (class 0x02, subclass 0x02) + a CDC data interface (0x0A)
  bool hid = false;          // class 0x03
  bool dfu_runtime = false;  // class 0xFE subclass 0x01 protocol 1
  bool dfu_mode = false;     // class 0xFE subclass 0x01 protocol 2
};

struct AttachedDevice {
  enum class Kind { kHand, kRomBootloader };
  Kind kind = Kind::kHand;
  std::uint8_t bus = 0;
  std::uint8_t address = 0;
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::string port_path;  // "1-2.3" (bus-port.port...), stable while the cable stays put
  // Empty (and `access_denied` or `read_error` set) when the device could
  // not be opened or its strings not read.
  std::string serial;
  std::string product;
  // kHand: from iConfiguration, "fw <version> model <16 hex digits> (<source>)"
  // (firmware/usb/running_model.h): the running model's hash and where it
  // comes from ("factory", "slot A, sequence 2"; empty from a firmware that
  // does not say).
  std::string firmware_version;
  std::string model_hash;
  std::string model_source;
  InterfacesPresent interfaces;
  bool access_denied = false;  // LIBUSB_ERROR_ACCESS on open: udev rules missing
  std::string read_error;      // any other failure, in words
};

// Every hand and ROM bootloader on the buses `context` sees, in bus/address
// order. Throws std::runtime_error only if libusb cannot list devices at all.
std::vector<AttachedDevice> list_attached_devices(libusb_context* context);

// The configuration string of a hand.
struct ConfigurationString {
  std::string firmware_version;  // "0.1.0"
  std::string model_hash;        // 16 hex digits
  std::string model_source;      // "factory", "slot A, sequence 2"; "" if the text has none
};

// "fw 0.1.0 model 0123456789abcdef (slot B, sequence 2)" (or without the
// parenthesis: older firmware) -> its parts; false (`out` unchanged) for
// any other text.
bool parse_configuration_string(const std::string& text, ConfigurationString& out);

}  // namespace hadynet::tools::usb

#endif  // HADYNET_TOOLS_USB_USB_INVENTORY_H_
