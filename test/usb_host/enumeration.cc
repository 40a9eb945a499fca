#include "test/usb_host/enumeration.h"

#include <cstdio>

namespace hadynet::usb::host_testing {
namespace {

// A string descriptor (LANGID 0x0409) as ASCII; empty if absent or refused.
std::string read_string(UrbEngine& e, std::uint8_t index) {
  std::string out;
  if (index == 0) return out;
  int status = 0;
  const std::vector<std::uint8_t> d = e.control_in(
      request::kGetDescriptor, static_cast<std::uint16_t>((descriptor::kString << 8) | index), 0x0409, 255, status);
  if (status != 0 || d.size() < 2 || d[1] != descriptor::kString) return out;
  for (std::size_t i = 2; i + 1 < d.size() && i < d[0]; i += 2) out.push_back(static_cast<char>(d[i]));
  return out;
}

std::string hex(const std::vector<std::uint8_t>& bytes) {
  std::string out;
  char b[3];
  for (const std::uint8_t v : bytes) {
    std::snprintf(b, sizeof b, "%02x", v);
    out += b;
  }
  return out;
}

}  // namespace

std::string EnumeratedDevice::devnode() const {
  char path[32];
  std::snprintf(path, sizeof path, "/dev/bus/usb/%03u/%03u", busnum, devnum);
  return path;
}

std::string EnumeratedDevice::syspath() const {
  return "/sys/devices/pci0000:00/0000:00:14.0/usb" + std::to_string(busnum) + "/" + std::to_string(busnum) + "-" +
         std::to_string(devnum);
}

bool EnumeratedDevice::has_alternate(unsigned interface, unsigned alt) const {
  for (std::size_t i = 0; i + 3 < configuration.size() && configuration[i] != 0; i += configuration[i]) {
    const std::uint8_t* d = configuration.data() + i;
    if (d[1] == descriptor::kInterface && d[2] == interface && d[3] == alt) return true;
  }
  return false;
}

std::string enumerate(UrbEngine& e, std::uint8_t busnum, std::uint8_t devnum, EnumeratedDevice& out) {
  out = EnumeratedDevice{};
  out.busnum = busnum;
  out.devnum = devnum;
  int status = 0;
  e.device().controller().bus_reset();
  out.device_descriptor = e.control_in(request::kGetDescriptor, descriptor::kDevice << 8, 0, 18, status);
  if (status != 0 || out.device_descriptor.size() != 18) {
    return "GET_DESCRIPTOR(device) failed: status " + std::to_string(status);
  }
  const std::uint8_t std_out = request_type(false, RequestKind::kStandard, Recipient::kDevice);
  if (e.sync_control(std_out, request::kSetAddress, devnum, 0) != 0) return "SET_ADDRESS refused";
  const std::vector<std::uint8_t> head =
      e.control_in(request::kGetDescriptor, descriptor::kConfiguration << 8, 0, 9, status);
  if (status != 0 || head.size() != 9) return "GET_DESCRIPTOR(configuration, 9) failed";
  const std::uint16_t total = le16(head.data() + 2);
  out.configuration = e.control_in(request::kGetDescriptor, descriptor::kConfiguration << 8, 0, total, status);
  if (status != 0 || out.configuration.size() != total) return "GET_DESCRIPTOR(configuration, wTotalLength) failed";
  out.manufacturer = read_string(e, out.device_descriptor[14]);
  out.product = read_string(e, out.device_descriptor[15]);
  out.serial = read_string(e, out.device_descriptor[16]);
  out.configuration_name = read_string(e, out.configuration[6]);
  if (e.sync_control(std_out, request::kSetConfiguration, out.configuration[5], 0) != 0) {
    return "SET_CONFIGURATION refused";
  }
  return "";
}

std::string sysfs_record(const EnumeratedDevice& e) {
  char bus[4], dev[4];
  std::snprintf(bus, sizeof bus, "%03u", e.busnum);
  std::snprintf(dev, sizeof dev, "%03u", e.devnum);
  const std::uint8_t* d = e.device_descriptor.data();
  const std::uint8_t* c = e.configuration.data();
  char ids[160];
  std::snprintf(ids, sizeof ids,
                "A: idVendor=%04x\\n\nA: idProduct=%04x\\n\nA: bcdDevice=%04x\\n\nA: bDeviceClass=%02x\\n\n"
                "A: bDeviceSubClass=%02x\\n\nA: bDeviceProtocol=%02x\\n\n",
                le16(d + 8), le16(d + 10), le16(d + 12), d[4], d[5], d[6]);
  char config[200];
  std::snprintf(config, sizeof config,
                "A: bConfigurationValue=%u\\n\nA: bNumConfigurations=%u\\n\nA: bNumInterfaces=%2u\\n\n"
                "A: bmAttributes=%02x\\n\nA: MaxPower=%umA\\n\nA: bMaxPacketSize0=%u\\n\n",
                c[5], d[17], c[4], c[7], c[8] * 2u, d[7]);
  std::vector<std::uint8_t> descriptors = e.device_descriptor;
  for (const std::uint8_t b : e.configuration) descriptors.push_back(b);  // (insert: GCC 12 -Warray-bounds noise)
  const auto optional = [](const char* name, const std::string& value) {
    return value.empty() ? std::string() : std::string("A: ") + name + "=" + value + "\\n\n";
  };
  const std::string port = std::to_string(e.devnum);  // one root port per devnum: devpath = devnum
  return "P: " + e.syspath().substr(4) + "\n" +                                                       //
         "N: bus/usb/" + bus + "/" + dev + "\n" +                                                     //
         "E: SUBSYSTEM=usb\nE: DEVTYPE=usb_device\nE: DRIVER=usb\n" +                                 //
         "E: BUSNUM=" + bus + "\nE: DEVNUM=" + dev + "\nE: DEVNAME=" + e.devnode() + "\n" +           //
         "A: busnum=" + std::to_string(e.busnum) + "\\n\nA: devnum=" + std::to_string(e.devnum) + "\\n\n" +  //
         "A: devpath=" + port + "\\n\nA: speed=12\\n\nA: version= 2.00\\n\nA: maxchild=0\\n\n" + ids + config +
         optional("manufacturer", e.manufacturer) + optional("product", e.product) + optional("serial", e.serial) +
         optional("configuration", e.configuration_name) +  //
         "H: descriptors=" + hex(descriptors) + "\n";
}

}  // namespace hadynet::usb::host_testing
