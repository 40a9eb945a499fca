#include "tools/usb/libusb_dfu.h"

#include <libusb.h>

#include <memory>
#include <stdexcept>

namespace hadynet::tools::usb {
namespace {

constexpr std::uint8_t kDfuFunctionalType = 0x21;
// bmRequestType of DFU's class requests (USB 2.0 §9.3.1): class, interface, OUT / IN.
constexpr std::uint8_t kClassInterfaceOut = 0x21;
constexpr std::uint8_t kClassInterfaceIn = 0xA1;

struct ConfigDeleter {
  void operator()(libusb_config_descriptor* c) const { libusb_free_config_descriptor(c); }
};

UsbTransferError transfer_error(int code, std::uint8_t request) {
  const std::string what = "DFU request " + std::to_string(request) + ": " + libusb_strerror(code);
  switch (code) {
    case LIBUSB_ERROR_PIPE: return {UsbTransferError::Kind::kStall, what + " (the device STALLed it)"};
    case LIBUSB_ERROR_NO_DEVICE: return {UsbTransferError::Kind::kGone, what};
    case LIBUSB_ERROR_TIMEOUT: return {UsbTransferError::Kind::kTimeout, what};
    default: return {UsbTransferError::Kind::kOther, what};
  }
}

std::unique_ptr<libusb_config_descriptor, ConfigDeleter> config_of(libusb_device* device) {
  libusb_config_descriptor* raw = nullptr;
  if (libusb_get_active_config_descriptor(device, &raw) != LIBUSB_SUCCESS &&
      libusb_get_config_descriptor(device, 0, &raw) != LIBUSB_SUCCESS) {
    throw std::runtime_error("cannot read the device's configuration descriptor");
  }
  return std::unique_ptr<libusb_config_descriptor, ConfigDeleter>(raw);
}

std::string open_error(int code) {
  if (code == LIBUSB_ERROR_ACCESS) {
    return "permission denied opening the device: install udev/60-hadynet.rules (docs/usb.md) and re-plug";
  }
  return std::string("cannot open the device: ") + libusb_strerror(code);
}

}  // namespace

int find_dfu_interface(libusb_device* device, std::uint8_t protocol) {
  const auto config = config_of(device);
  for (int i = 0; i < config->bNumInterfaces; ++i) {
    const libusb_interface& itf = config->interface[i];
    for (int a = 0; a < itf.num_altsetting; ++a) {
      const libusb_interface_descriptor& d = itf.altsetting[a];
      if (d.bInterfaceClass == LIBUSB_CLASS_APPLICATION && d.bInterfaceSubClass == 0x01 &&
          d.bInterfaceProtocol == protocol) {
        return d.bInterfaceNumber;
      }
    }
  }
  return -1;
}

LibusbDfuInterface::LibusbDfuInterface(libusb_device* device, std::uint8_t interface_number, std::uint8_t alternate)
    : interface_(interface_number) {
  const auto config = config_of(device);
  const libusb_interface* itf = nullptr;
  for (int i = 0; i < config->bNumInterfaces; ++i) {
    if (config->interface[i].num_altsetting > 0 &&
        config->interface[i].altsetting[0].bInterfaceNumber == interface_number) {
      itf = &config->interface[i];
    }
  }
  if (itf == nullptr) throw std::runtime_error("the device has no interface " + std::to_string(interface_number));
  // The functional descriptor follows the interface descriptor (class-specific extra bytes).
  for (int a = 0; a < itf->num_altsetting && functional_.transfer_size == 0; ++a) {
    const libusb_interface_descriptor& d = itf->altsetting[a];
    for (int at = 0; at + 9 <= d.extra_length; at += d.extra[at] > 0 ? d.extra[at] : d.extra_length) {
      if (d.extra[at] >= 9 && d.extra[at + 1] == kDfuFunctionalType) {
        functional_.attributes = d.extra[at + 2];
        functional_.detach_timeout_ms = static_cast<std::uint16_t>(d.extra[at + 3] | (d.extra[at + 4] << 8));
        functional_.transfer_size = static_cast<std::uint16_t>(d.extra[at + 5] | (d.extra[at + 6] << 8));
        functional_.dfu_version_bcd = static_cast<std::uint16_t>(d.extra[at + 7] | (d.extra[at + 8] << 8));
        break;
      }
    }
  }
  if (functional_.transfer_size == 0) {
    throw std::runtime_error("interface " + std::to_string(interface_number) +
                             " has no DFU functional descriptor with a wTransferSize");
  }
  if (alternate >= itf->num_altsetting) {
    throw std::runtime_error("interface " + std::to_string(interface_number) + " has no alternate setting " +
                             std::to_string(alternate));
  }
  if (const int r = libusb_open(device, &handle_); r != LIBUSB_SUCCESS) throw std::runtime_error(open_error(r));
  for (int a = 0; a < itf->num_altsetting; ++a) {
    unsigned char text[256];
    const int n = libusb_get_string_descriptor_ascii(handle_, itf->altsetting[a].iInterface, text, sizeof text);
    alternate_names_.emplace_back(n > 0 ? std::string(reinterpret_cast<char*>(text), static_cast<std::size_t>(n))
                                        : std::string());
  }
  libusb_set_auto_detach_kernel_driver(handle_, 1);
  if (const int r = libusb_claim_interface(handle_, interface_); r != LIBUSB_SUCCESS) {
    libusb_close(handle_);
    handle_ = nullptr;
    throw std::runtime_error(std::string("cannot claim DFU interface ") + std::to_string(interface_) + ": " +
                             libusb_strerror(r) + (r == LIBUSB_ERROR_BUSY ? " (another program uses it)" : ""));
  }
  if (itf->num_altsetting > 1) {
    if (const int r = libusb_set_interface_alt_setting(handle_, interface_, alternate); r != LIBUSB_SUCCESS) {
      libusb_release_interface(handle_, interface_);
      libusb_close(handle_);
      handle_ = nullptr;
      throw std::runtime_error(std::string("cannot select alternate setting ") + std::to_string(alternate) + ": " +
                               libusb_strerror(r));
    }
  }
}

LibusbDfuInterface::~LibusbDfuInterface() {
  if (handle_ == nullptr) return;
  libusb_release_interface(handle_, interface_);  // fails harmlessly if the device is gone
  libusb_close(handle_);
}

void LibusbDfuInterface::control_out(std::uint8_t request, std::uint16_t value, std::span<const std::uint8_t> data) {
  const int r = libusb_control_transfer(handle_, kClassInterfaceOut, request, value, interface_,
                                        const_cast<unsigned char*>(data.data()), static_cast<std::uint16_t>(data.size()),
                                        kControlTimeoutMs);
  if (r < 0) throw transfer_error(r, request);
  if (static_cast<std::size_t>(r) != data.size()) {
    throw UsbTransferError(UsbTransferError::Kind::kOther, "DFU request " + std::to_string(request) + ": sent " +
                                                               std::to_string(r) + " of " +
                                                               std::to_string(data.size()) + " bytes");
  }
}

std::size_t LibusbDfuInterface::control_in(std::uint8_t request, std::uint16_t value, std::span<std::uint8_t> buffer) {
  const int r = libusb_control_transfer(handle_, kClassInterfaceIn, request, value, interface_, buffer.data(),
                                        static_cast<std::uint16_t>(buffer.size()), kControlTimeoutMs);
  if (r < 0) throw transfer_error(r, request);
  return static_cast<std::size_t>(r);
}

std::string LibusbDfuInterface::string_descriptor(std::uint8_t index) {
  if (index == 0 || handle_ == nullptr) return {};
  unsigned char text[256];
  const int n = libusb_get_string_descriptor_ascii(handle_, index, text, sizeof text);
  return n > 0 ? std::string(reinterpret_cast<char*>(text), static_cast<std::size_t>(n)) : std::string();
}

void detach_to_bootloader(libusb_device* device, std::uint8_t runtime_interface) {
  libusb_device_handle* handle = nullptr;
  if (const int r = libusb_open(device, &handle); r != LIBUSB_SUCCESS) throw std::runtime_error(open_error(r));
  libusb_set_auto_detach_kernel_driver(handle, 1);
  int r = libusb_claim_interface(handle, runtime_interface);
  if (r == LIBUSB_SUCCESS) {
    // wValue: how long the device waits for a reset (ours detaches itself).
    r = libusb_control_transfer(handle, kClassInterfaceOut, dfu::kDetach, 1000, runtime_interface, nullptr, 0,
                                kControlTimeoutMs);
    libusb_release_interface(handle, runtime_interface);
  }
  libusb_close(handle);
  // The device resets right after the status stage: a vanished device or an
  // I/O error on the way out still means the request was taken.
  if (r < 0 && r != LIBUSB_ERROR_NO_DEVICE && r != LIBUSB_ERROR_IO) {
    throw std::runtime_error(std::string("DFU_DETACH failed: ") + libusb_strerror(r));
  }
}

}  // namespace hadynet::tools::usb
