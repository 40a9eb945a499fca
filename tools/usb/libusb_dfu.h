// DFU over libusb-1.0: the DfuTransport of a claimed DFU interface, its
// functional descriptor and alternate-setting names, DFU_DETACH of a
// running device, and waiting for a device to (re)appear.
#ifndef HADYNET_TOOLS_USB_LIBUSB_DFU_H_
#define HADYNET_TOOLS_USB_LIBUSB_DFU_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tools/usb/dfu_client.h"

struct libusb_context;
struct libusb_device;
struct libusb_device_handle;

namespace hadynet::tools::usb {

inline constexpr unsigned kControlTimeoutMs = 5000;  // one control transfer

// The DFU functional descriptor (DFU 1.1 §4.1.3 / §4.2.4).
struct DfuFunctional {
  std::uint8_t attributes = 0;
  std::uint16_t detach_timeout_ms = 0;
  std::uint16_t transfer_size = 0;
  std::uint16_t dfu_version_bcd = 0;
};

// An opened device with one DFU interface claimed (released and closed by
// the destructor). Throws std::runtime_error in words when it cannot.
class LibusbDfuInterface final : public DfuTransport {
 public:
  LibusbDfuInterface(libusb_device* device, std::uint8_t interface_number, std::uint8_t alternate);
  ~LibusbDfuInterface() override;
  LibusbDfuInterface(const LibusbDfuInterface&) = delete;
  LibusbDfuInterface& operator=(const LibusbDfuInterface&) = delete;

  void control_out(std::uint8_t request, std::uint16_t value, std::span<const std::uint8_t> data) override;
  std::size_t control_in(std::uint8_t request, std::uint16_t value, std::span<std::uint8_t> buffer) override;

  const DfuFunctional& functional() const { return functional_; }
  // String descriptor `index` as ASCII (a GETSTATUS iString); "" if it
  // cannot be read or `index` is 0.
  std::string string_descriptor(std::uint8_t index);
  // The name of every alternate setting of the interface (iInterface), in order.
  const std::vector<std::string>& alternate_names() const { return alternate_names_; }

 private:
  libusb_device_handle* handle_ = nullptr;
  std::uint8_t interface_ = 0;
  DfuFunctional functional_;
  std::vector<std::string> alternate_names_;
};

// Opens `device`, claims its DFU runtime interface and sends DFU_DETACH.
// Throws std::runtime_error in words.
void detach_to_bootloader(libusb_device* device, std::uint8_t runtime_interface);

// The interface number of the first interface of class 0xFE/0x01 with the
// given protocol (1 runtime, 2 DFU mode) in the device's configuration.
int find_dfu_interface(libusb_device* device, std::uint8_t protocol);

}  // namespace hadynet::tools::usb

#endif  // HADYNET_TOOLS_USB_LIBUSB_DFU_H_
