// The USB fuzzer's seed inputs (usb_fuzz_harness.h format), shared by
// usb_make_corpus (writes them for libFuzzer) and the regular test suite
// (test/usb/fuzz_seed_test.cc runs them through the harness).
#ifndef HADYNET_FUZZ_USB_FUZZ_SEEDS_H_
#define HADYNET_FUZZ_USB_FUZZ_SEEDS_H_

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "fuzz/usb_fuzz_harness.h"

namespace hadynet::usb::fuzz::seeds {

using Bytes = std::vector<std::uint8_t>;

inline void op(Bytes& b, UsbFuzzOp o) { b.push_back(static_cast<std::uint8_t>(o)); }

inline void setup(Bytes& b, std::uint8_t type, std::uint8_t req, std::uint16_t value, std::uint16_t index,
                  std::uint16_t length) {
  op(b, UsbFuzzOp::kSetupRaw);
  for (const int v : {int{type}, int{req}, value & 0xFF, value >> 8, index & 0xFF, index >> 8, length & 0xFF,
                      length >> 8}) {
    b.push_back(static_cast<std::uint8_t>(v));
  }
}

inline void in_tokens(Bytes& b, std::uint8_t ep, int n) {
  for (int i = 0; i < n; ++i) {
    op(b, UsbFuzzOp::kInToken);
    b.push_back(ep);
  }
}

// A class request to `interface` (whole transfer); `length` even, <= 510.
inline void class_control(Bytes& b, std::uint8_t interface, std::uint8_t request, bool in, std::uint16_t value,
                          const Bytes& data, std::uint16_t in_length = 0) {
  op(b, UsbFuzzOp::kClassControl);
  b.push_back(interface);
  b.push_back(static_cast<std::uint8_t>(request | (in ? 0x80 : 0)));
  b.push_back(static_cast<std::uint8_t>(value));
  b.push_back(static_cast<std::uint8_t>(value >> 8));
  b.push_back(static_cast<std::uint8_t>((in ? in_length : data.size()) / 2));
  if (!in) b.insert(b.end(), data.begin(), data.end());
}

inline Bytes dfu_download(bool fault) {
  Bytes b;
  op(b, UsbFuzzOp::kEnumerate);
  if (fault) {
    op(b, UsbFuzzOp::kFlashFault);
    b.push_back(1);
    b.push_back(1);
  }
  Bytes payload(100);
  for (std::size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<std::uint8_t>(i * 13);
  const std::uint32_t crc = hadynet::link::crc32(payload);
  Bytes image = {'H', 'D', 'I', 'M', 1, 0, 0, 0, 100, 0, 0, 0};
  for (int k = 0; k < 4; ++k) image.push_back(static_cast<std::uint8_t>(crc >> (8 * k)));
  image.insert(image.end(), payload.begin(), payload.end());  // 116 bytes (even)
  class_control(b, 4, 1, false, 0, image);                    // DNLOAD block 0
  for (int i = 0; i < 2; ++i) {
    class_control(b, 4, 3, true, 0, {}, 6);  // GETSTATUS
    op(b, UsbFuzzOp::kService);
  }
  class_control(b, 4, 3, true, 0, {}, 6);
  class_control(b, 4, 1, false, 1, {});  // DNLOAD zero length
  for (int i = 0; i < 2; ++i) {
    class_control(b, 4, 3, true, 0, {}, 6);
    op(b, UsbFuzzOp::kService);
  }
  class_control(b, 4, 3, true, 0, {}, 6);
  class_control(b, 4, 2, true, 0, {}, 256);  // UPLOAD
  if (fault) class_control(b, 4, 4, false, 0, {});  // CLRSTATUS (leaves dfuERROR)
  return b;
}


inline Bytes enumerate_and_read_descriptors() {
  Bytes b;
  op(b, UsbFuzzOp::kBusReset);
  setup(b, 0x80, 6, 0x0100, 0, 64);
  in_tokens(b, 0x80, 1);
  op(b, UsbFuzzOp::kOutToken);
  b.push_back(0);
  b.push_back(0);
  setup(b, 0x00, 5, 9, 0, 0);
  in_tokens(b, 0x80, 1);
  setup(b, 0x80, 6, 0x0200, 0, 255);
  in_tokens(b, 0x80, 4);
  op(b, UsbFuzzOp::kOutToken);
  b.push_back(0);
  b.push_back(0);
  setup(b, 0x00, 9, 1, 0, 0);
  in_tokens(b, 0x80, 1);
  return b;
}

inline Bytes cdc_traffic() {
  Bytes b;
  op(b, UsbFuzzOp::kEnumerate);
  class_control(b, 0, 0x20, false, 0, {0x00, 0xC2, 0x01, 0x00, 0, 0, 8, 0});  // SET_LINE_CODING (8 bytes: even)
  class_control(b, 0, 0x21, true, 0, {}, 8);
  for (int k = 0; k < 3; ++k) {
    op(b, UsbFuzzOp::kOutToken);
    b.push_back(2);
    b.push_back(64);
    for (int i = 0; i < 64; ++i) b.push_back(static_cast<std::uint8_t>(i + k));
    op(b, UsbFuzzOp::kService);
    in_tokens(b, 0x82, 4);
  }
  op(b, UsbFuzzOp::kPublish);
  b.push_back(1);
  in_tokens(b, 0x83, static_cast<int>(TelemetryLayout<Q>::kParts));  // one whole report set
  return b;
}

// (file name, input) of every seed.
inline std::vector<std::pair<std::string, Bytes>> all() {
  return {{"enumerate.bin", enumerate_and_read_descriptors()},
          {"cdc.bin", cdc_traffic()},
          {"dfu_download.bin", dfu_download(false)},
          {"dfu_download_power_cut.bin", dfu_download(true)}};
}

}  // namespace hadynet::usb::fuzz::seeds

#endif  // HADYNET_FUZZ_USB_FUZZ_SEEDS_H_
