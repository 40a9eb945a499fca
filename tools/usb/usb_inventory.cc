#include "tools/usb/usb_inventory.h"

#include <libusb.h>

#include <algorithm>
#include <cctype>
#include <memory>
#include <stdexcept>
#include <string_view>

#include "firmware/usb/usb_identity.h"

namespace hadynet::tools::usb {
namespace {


struct DeviceListDeleter {
  void operator()(libusb_device** list) const { libusb_free_device_list(list, 1); }
};
struct ConfigDeleter {
  void operator()(libusb_config_descriptor* c) const { libusb_free_config_descriptor(c); }
};
struct HandleCloser {
  void operator()(libusb_device_handle* h) const { libusb_close(h); }
};

std::string port_path_of(libusb_device* device) {
  std::uint8_t ports[8];
  const int n = libusb_get_port_numbers(device, ports, sizeof ports);
  std::string path = std::to_string(libusb_get_bus_number(device));
  for (int i = 0; i < n; ++i) path += (i == 0 ? "-" : ".") + std::to_string(ports[i]);
  return path;
}

InterfacesPresent interfaces_of(libusb_device* device) {
  InterfacesPresent present;
  libusb_config_descriptor* raw = nullptr;
  if (libusb_get_active_config_descriptor(device, &raw) != LIBUSB_SUCCESS &&
      libusb_get_config_descriptor(device, 0, &raw) != LIBUSB_SUCCESS) {
    return present;
  }
  const std::unique_ptr<libusb_config_descriptor, ConfigDeleter> config(raw);
  bool comm = false, data = false;
  for (int i = 0; i < config->bNumInterfaces; ++i) {
    const libusb_interface& itf = config->interface[i];
    for (int a = 0; a < itf.num_altsetting; ++a) {
      const libusb_interface_descriptor& d = itf.altsetting[a];
      if (d.bInterfaceClass == LIBUSB_CLASS_COMM && d.bInterfaceSubClass == 0x02) comm = true;
      if (d.bInterfaceClass == LIBUSB_CLASS_DATA) data = true;
      if (d.bInterfaceClass == LIBUSB_CLASS_HID) present.hid = true;
      if (d.bInterfaceClass == LIBUSB_CLASS_APPLICATION && d.bInterfaceSubClass == 0x01) {
        if (d.bInterfaceProtocol == 1) present.dfu_runtime = true;
        if (d.bInterfaceProtocol == 2) present.dfu_mode = true;
      }
    }
  }
  present.cdc_acm = comm && data;
  return present;
}

std::string read_string(libusb_device_handle* handle, std::uint8_t index, std::string& error) {
  if (index == 0) return {};
  unsigned char text[256];
  const int n = libusb_get_string_descriptor_ascii(handle, index, text, sizeof text);
  if (n < 0) {
    if (error.empty()) error = std::string("string descriptor ") + std::to_string(index) + ": " + libusb_strerror(n);
    return {};
  }
  return std::string(reinterpret_cast<const char*>(text), static_cast<std::size_t>(n));
}

void read_strings(libusb_device* device, const libusb_device_descriptor& desc, AttachedDevice& out) {
  libusb_device_handle* raw = nullptr;
  const int opened = libusb_open(device, &raw);
  if (opened == LIBUSB_ERROR_ACCESS) {
    out.access_denied = true;
    return;
  }
  if (opened != LIBUSB_SUCCESS) {
    out.read_error = std::string("open: ") + libusb_strerror(opened);
    return;
  }
  const std::unique_ptr<libusb_device_handle, HandleCloser> handle(raw);
  out.serial = read_string(handle.get(), desc.iSerialNumber, out.read_error);
  out.product = read_string(handle.get(), desc.iProduct, out.read_error);
  if (out.kind != AttachedDevice::Kind::kHand) return;
  libusb_config_descriptor* config_raw = nullptr;
  if (libusb_get_config_descriptor(device, 0, &config_raw) != LIBUSB_SUCCESS) return;
  const std::unique_ptr<libusb_config_descriptor, ConfigDeleter> config(config_raw);
  const std::string text = read_string(handle.get(), config->iConfiguration, out.read_error);
  ConfigurationString parsed;
  if (!text.empty() && parse_configuration_string(text, parsed)) {
    out.firmware_version = parsed.firmware_version;
    out.model_hash = parsed.model_hash;
    out.model_source = parsed.model_source;
  } else if (!text.empty() && out.read_error.empty()) {
    out.read_error = "configuration string '" + text + "' is not 'fw <version> model <hash> (<source>)'";
  }
}

}  // namespace

bool parse_configuration_string(const std::string& text, ConfigurationString& out) {
  constexpr std::string_view kFw = "fw ", kModel = " model ";
  constexpr std::size_t kHashDigits = 16;
  if (text.compare(0, kFw.size(), kFw) != 0) return false;
  const std::size_t at = text.find(kModel, kFw.size());
  if (at == std::string::npos || at == kFw.size()) return false;
  const std::string hash = text.substr(at + kModel.size(), kHashDigits);
  if (hash.size() != kHashDigits) return false;
  if (!std::all_of(hash.begin(), hash.end(), [](unsigned char c) { return std::isxdigit(c) != 0; })) return false;
  const std::string rest = text.substr(at + kModel.size() + kHashDigits);
  std::string source;
  if (!rest.empty()) {
    if (rest.size() < 3 || rest.compare(0, 2, " (") != 0 || rest.back() != ')') return false;
    source = rest.substr(2, rest.size() - 3);
  }
  out.firmware_version = text.substr(kFw.size(), at - kFw.size());
  out.model_hash = hash;
  out.model_source = source;
  return true;
}

std::vector<AttachedDevice> list_attached_devices(libusb_context* context) {
  libusb_device** raw = nullptr;
  const ssize_t count = libusb_get_device_list(context, &raw);
  if (count < 0) {
    throw std::runtime_error(std::string("cannot list USB devices: ") + libusb_strerror(static_cast<int>(count)));
  }
  const std::unique_ptr<libusb_device*, DeviceListDeleter> list(raw);
  std::vector<AttachedDevice> found;
  for (ssize_t i = 0; i < count; ++i) {
    libusb_device* device = list.get()[i];
    libusb_device_descriptor desc;
    if (libusb_get_device_descriptor(device, &desc) != LIBUSB_SUCCESS) continue;
    AttachedDevice d;
    if (desc.idVendor == hadynet::usb::kHadynetUsbIdentity.vendor_id &&
        desc.idProduct == hadynet::usb::kHadynetUsbIdentity.product_id) {
      d.kind = AttachedDevice::Kind::kHand;
    } else if (desc.idVendor == kStmVendorId && desc.idProduct == kStmDfuProductId) {
      d.kind = AttachedDevice::Kind::kRomBootloader;
    } else {
      continue;
    }
    d.bus = libusb_get_bus_number(device);
    d.address = libusb_get_device_address(device);
    d.vendor_id = desc.idVendor;
    d.product_id = desc.idProduct;
    d.port_path = port_path_of(device);
    d.interfaces = interfaces_of(device);
    read_strings(device, desc, d);
    found.push_back(std::move(d));
  }
  std::sort(found.begin(), found.end(), [](const AttachedDevice& a, const AttachedDevice& b) {
    return a.bus != b.bus ? a.bus < b.bus : a.address < b.address;
  });
  return found;
}

}  // namespace hadynet::tools::usb
