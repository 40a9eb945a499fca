// An independent parser and checker of USB 2.0 descriptor sets, written for
// the tests from the specification (USB 2.0 ch. 9, the IAD ECN, CDC 1.2,
// HID 1.11, DFU 1.1), not from the code under test. It reports every
// violation as a readable string.
#ifndef HADYNET_TEST_USB_DESCRIPTOR_PARSER_H_
#define HADYNET_TEST_USB_DESCRIPTOR_PARSER_H_

#include <cstdint>
#include <string>
#include <vector>

namespace hadynet::usb::testing {

struct ParsedEndpoint {
  std::uint8_t address = 0;
  std::uint8_t attributes = 0;
  std::uint16_t max_packet = 0;
  std::uint8_t interval = 0;
};

struct ParsedInterface {
  std::uint8_t number = 0;
  std::uint8_t alternate = 0;
  std::uint8_t num_endpoints = 0;
  std::uint8_t cls = 0, subclass = 0, protocol = 0;
  std::uint8_t name = 0;  // iInterface
  std::vector<ParsedEndpoint> endpoints;
  std::vector<std::vector<std::uint8_t>> class_descriptors;  // class-specific, in order
};

struct ParsedIad {
  std::uint8_t first_interface = 0, count = 0, cls = 0, subclass = 0, protocol = 0, name = 0;
};

struct ParsedConfiguration {
  std::uint16_t total_length = 0;
  std::uint8_t num_interfaces = 0;
  std::uint8_t value = 0;
  std::uint8_t name = 0;  // iConfiguration
  std::uint8_t attributes = 0;
  std::uint8_t max_power = 0;
  std::vector<ParsedInterface> interfaces;  // every alternate setting, in order
  std::vector<ParsedIad> iads;
  std::vector<std::uint8_t> string_indices;  // every non-zero string index referenced
};

// Parses and checks a configuration descriptor set; appends violations to
// `errors`.
ParsedConfiguration parse_configuration(const std::vector<std::uint8_t>& bytes, std::vector<std::string>& errors);

// Checks an 18-byte device descriptor (USB 2.0 table 9-8) for a full-speed
// composite device with IADs; appends violations.
void check_device_descriptor(const std::vector<std::uint8_t>& bytes, std::vector<std::string>& errors);

// Checks a string descriptor; returns its text (ASCII only, '?' otherwise).
std::string parse_string_descriptor(const std::vector<std::uint8_t>& bytes, std::vector<std::string>& errors);

}  // namespace hadynet::usb::testing

#endif  // HADYNET_TEST_USB_DESCRIPTOR_PARSER_H_
