#include "descriptor_parser.h"

#include <map>
#include <set>
#include <sstream>

namespace hadynet::usb::testing {

namespace {

std::uint16_t le16(const std::vector<std::uint8_t>& b, std::size_t i) {
  return static_cast<std::uint16_t>(b[i] | (b[i + 1] << 8));
}

std::string hex(unsigned v) {
  std::ostringstream s;
  s << "0x" << std::hex << v;
  return s.str();
}

}  // namespace

void check_device_descriptor(const std::vector<std::uint8_t>& d, std::vector<std::string>& errors) {
  if (d.size() != 18) {
    errors.push_back("device descriptor is " + std::to_string(d.size()) + " bytes, not 18");
    return;
  }
  if (d[0] != 18) errors.push_back("device bLength " + std::to_string(d[0]));
  if (d[1] != 1) errors.push_back("device bDescriptorType " + std::to_string(d[1]));
  if (le16(d, 2) != 0x0200) errors.push_back("bcdUSB " + hex(le16(d, 2)) + ", expected 0x200");
  // A composite device with IADs must say so in the device class (IAD ECN).
  if (d[4] != 0xEF || d[5] != 0x02 || d[6] != 0x01) errors.push_back("device class is not EF/02/01");
  if (d[7] != 8 && d[7] != 16 && d[7] != 32 && d[7] != 64) errors.push_back("bMaxPacketSize0 " + std::to_string(d[7]));
  if (d[17] != 1) errors.push_back("bNumConfigurations " + std::to_string(d[17]));
}

std::string parse_string_descriptor(const std::vector<std::uint8_t>& d, std::vector<std::string>& errors) {
  if (d.size() < 2 || d[0] != d.size() || d[1] != 3 || d.size() % 2 != 0) {
    errors.push_back("malformed string descriptor");
    return {};
  }
  std::string text;
  for (std::size_t i = 2; i + 1 < d.size(); i += 2) {
    const unsigned unit = le16(d, i);
    text.push_back(unit < 0x80 ? static_cast<char>(unit) : '?');
  }
  return text;
}

ParsedConfiguration parse_configuration(const std::vector<std::uint8_t>& b, std::vector<std::string>& errors) {
  ParsedConfiguration c;
  if (b.size() < 9 || b[0] != 9 || b[1] != 2) {
    errors.push_back("no configuration header");
    return c;
  }
  c.total_length = le16(b, 2);
  c.num_interfaces = b[4];
  c.value = b[5];
  c.name = b[6];
  c.attributes = b[7];
  c.max_power = b[8];
  if (c.total_length != b.size()) {
    errors.push_back("wTotalLength " + std::to_string(c.total_length) + " != " + std::to_string(b.size()) + " bytes");
  }
  if ((c.attributes & 0x80) == 0) errors.push_back("bmAttributes bit 7 must be 1");
  if ((c.attributes & 0x1F) != 0) errors.push_back("bmAttributes reserved bits set");
  if (c.value == 0) errors.push_back("bConfigurationValue 0 is reserved");
  if (c.name != 0) c.string_indices.push_back(c.name);

  ParsedInterface* current = nullptr;
  for (std::size_t i = 9; i < b.size();) {
    const std::uint8_t len = b[i];
    if (len < 2 || i + len > b.size()) {
      errors.push_back("descriptor at offset " + std::to_string(i) + " has bad length " + std::to_string(len));
      break;
    }
    const std::uint8_t type = b[i + 1];
    const std::vector<std::uint8_t> d(b.begin() + static_cast<long>(i), b.begin() + static_cast<long>(i + len));
    if (type == 4) {
      if (len != 9) errors.push_back("interface descriptor length " + std::to_string(len));
      ParsedInterface f;
      f.number = d[2];
      f.alternate = d[3];
      f.num_endpoints = d[4];
      f.cls = d[5];
      f.subclass = d[6];
      f.protocol = d[7];
      f.name = d[8];
      if (f.name != 0) c.string_indices.push_back(f.name);
      c.interfaces.push_back(f);
      current = &c.interfaces.back();
    } else if (type == 5) {
      if (len != 7) errors.push_back("endpoint descriptor length " + std::to_string(len));
      if (current == nullptr) {
        errors.push_back("endpoint before any interface");
      } else {
        current->endpoints.push_back({d[2], d[3], le16(d, 4), d[6]});
      }
    } else if (type == 11) {
      if (len != 8) errors.push_back("IAD length " + std::to_string(len));
      c.iads.push_back({d[2], d[3], d[4], d[5], d[6], d[7]});
      if (d[7] != 0) c.string_indices.push_back(d[7]);
      if (current != nullptr && current->number >= d[2]) errors.push_back("IAD after its first interface");
    } else if (type == 1 || type == 2 || type == 3 || type == 6 || type == 7) {
      errors.push_back("standard descriptor type " + std::to_string(type) + " inside a configuration");
    } else {
      if (current == nullptr) {
        errors.push_back("class descriptor before any interface");
      } else {
        current->class_descriptors.push_back(d);
      }
    }
    i += len;
  }

  // Interface numbering: 0 .. bNumInterfaces-1, each with alternate 0 first
  // and alternates counting up by one.
  std::map<std::uint8_t, int> next_alt;
  for (const ParsedInterface& f : c.interfaces) {
    const int expected = next_alt.count(f.number) ? next_alt[f.number] : 0;
    if (f.alternate != expected) {
      errors.push_back("interface " + std::to_string(f.number) + " alternate " + std::to_string(f.alternate) +
                       ", expected " + std::to_string(expected));
    }
    next_alt[f.number] = f.alternate + 1;
    if (f.endpoints.size() != f.num_endpoints) {
      errors.push_back("interface " + std::to_string(f.number) + " declares " + std::to_string(f.num_endpoints) +
                       " endpoints, has " + std::to_string(f.endpoints.size()));
    }
  }
  if (next_alt.size() != c.num_interfaces) {
    errors.push_back("bNumInterfaces " + std::to_string(c.num_interfaces) + " but " +
                     std::to_string(next_alt.size()) + " interfaces");
  }
  for (std::uint8_t n = 0; n < c.num_interfaces; ++n) {
    if (!next_alt.count(n)) errors.push_back("interface number " + std::to_string(n) + " missing");
  }

  // Endpoints: numbers 1..15, never EP0, each address used by one interface
  // only (alternates of the same interface may reuse it), full-speed packet
  // limits, at most 3 non-zero endpoints per direction (STM32F405 OTG FS).
  std::map<std::uint8_t, std::uint8_t> owner;  // address -> interface
  std::set<std::uint8_t> in_numbers, out_numbers;
  for (const ParsedInterface& f : c.interfaces) {
    for (const ParsedEndpoint& e : f.endpoints) {
      const unsigned number = e.address & 0x0F;
      if (number == 0) errors.push_back("endpoint descriptor for EP0");
      if ((e.address & 0x70) != 0) errors.push_back("endpoint address reserved bits: " + hex(e.address));
      auto [it, inserted] = owner.emplace(e.address, f.number);
      if (!inserted && it->second != f.number) errors.push_back("endpoint " + hex(e.address) + " used twice");
      ((e.address & 0x80) ? in_numbers : out_numbers).insert(static_cast<std::uint8_t>(number));
      const unsigned type = e.attributes & 3;
      if ((e.attributes & 0xFC) != 0) errors.push_back("endpoint " + hex(e.address) + " attribute bits 2..7 set");
      if (type == 2 && e.max_packet != 8 && e.max_packet != 16 && e.max_packet != 32 && e.max_packet != 64) {
        errors.push_back("bulk endpoint " + hex(e.address) + " max packet " + std::to_string(e.max_packet));
      }
      if (type == 3 && (e.max_packet > 64 || e.max_packet == 0 || e.interval == 0)) {
        errors.push_back("interrupt endpoint " + hex(e.address) + " max packet/interval out of range");
      }
      if (type == 0 || type == 1) errors.push_back("control/isochronous endpoint " + hex(e.address));
    }
  }
  if (in_numbers.size() > 3) errors.push_back("more than 3 IN endpoints");
  if (out_numbers.size() > 3) errors.push_back("more than 3 OUT endpoints");
  for (const std::uint8_t n : in_numbers) {
    if (n > 3) errors.push_back("IN endpoint number " + std::to_string(n) + " > 3");
  }
  for (const std::uint8_t n : out_numbers) {
    if (n > 3) errors.push_back("OUT endpoint number " + std::to_string(n) + " > 3");
  }

  // IADs: contiguous interfaces that exist, at least 2, not overlapping, the
  // function class equal to its first interface's class.
  std::set<std::uint8_t> associated;
  for (const ParsedIad& a : c.iads) {
    if (a.count < 2) errors.push_back("IAD with fewer than 2 interfaces");
    for (unsigned k = a.first_interface; k < static_cast<unsigned>(a.first_interface) + a.count; ++k) {
      if (k >= c.num_interfaces) errors.push_back("IAD covers missing interface " + std::to_string(k));
      if (!associated.insert(static_cast<std::uint8_t>(k)).second) {
        errors.push_back("interface " + std::to_string(k) + " in two IADs");
      }
    }
    for (const ParsedInterface& f : c.interfaces) {
      if (f.number == a.first_interface && f.alternate == 0 && f.cls != a.cls) {
        errors.push_back("IAD class differs from its first interface's");
      }
    }
  }
  return c;
}

}  // namespace hadynet::usb::testing
