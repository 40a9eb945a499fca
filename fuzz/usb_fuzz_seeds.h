// The USB fuzzer's seed inputs (usb_fuzz_harness.h format), shared by
// usb_make_corpus (writes them for libFuzzer) and the regular test suite
// (test/usb/fuzz_seed_test.cc runs them through the harness). Host code:
// the model images are signed with libsodium.
#ifndef HADYNET_FUZZ_USB_FUZZ_SEEDS_H_
#define HADYNET_FUZZ_USB_FUZZ_SEEDS_H_

#include <sodium.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "firmware/model_update/model_image.h"
#include "fuzz/usb_fuzz_harness.h"
#include "fuzz/usb_fuzz_model.h"

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

// A signed model image for the harness's slots (usb_fuzz_model.h): header
// for fuzz_identity() with `sequence`, a payload from `seed`, signed with
// the key of kFuzzKeySeedByte (or another key: `stranger`), by libsodium.
inline Bytes signed_image(std::uint32_t sequence, std::uint8_t seed, bool stranger = false) {
  if (sodium_init() < 0) std::abort();
  std::array<std::uint8_t, crypto_sign_SEEDBYTES> key_seed{};
  key_seed.fill(stranger ? static_cast<std::uint8_t>(kFuzzKeySeedByte + 1) : kFuzzKeySeedByte);
  std::array<std::uint8_t, crypto_sign_PUBLICKEYBYTES> public_key{};
  std::array<std::uint8_t, crypto_sign_SECRETKEYBYTES> secret_key{};
  crypto_sign_seed_keypair(public_key.data(), secret_key.data(), key_seed.data());
  Bytes payload(kFuzzPayloadBytes);
  for (std::size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<std::uint8_t>(i * 13 + seed);
  const model_update::ModelIdentity id = fuzz_identity();
  model_update::ModelImageHeader h;
  h.contract_version = id.contract_version;
  h.numeric = id.numeric;
  h.sequence = sequence;
  h.shape_id = id.shape_id;
  h.payload_length = id.payload_length;
  h.model_hash = 0xF0220000u + seed;
  std::copy(public_key.begin(), public_key.end(), h.public_key.begin());
  crypto_hash_sha256(h.payload_sha256.data(), payload.data(), payload.size());
  Bytes image(model_update::kImageHeaderSize);
  const std::span<std::uint8_t, model_update::kImageHeaderSize> head(image.data(), model_update::kImageHeaderSize);
  model_update::encode_model_image_header(h, head);
  crypto_sign_detached(h.signature.data(), nullptr, image.data(), model_update::kSignedBytes, secret_key.data());
  model_update::encode_model_image_header(h, head);
  image.insert(image.end(), payload.begin(), payload.end());
  return image;
}

// DFU_GETSTATUS, then service() (the host's bwPollTimeout wait), twice, and
// a last GETSTATUS: a block or the manifestation is done.
inline void poll_through(Bytes& b) {
  for (int i = 0; i < 2; ++i) {
    class_control(b, 4, 3, true, 0, {}, 6);
    op(b, UsbFuzzOp::kService);
  }
  class_control(b, 4, 3, true, 0, {}, 6);
}

// `image` in 256-byte DNLOAD blocks (the last one shorter) on alternate 0,
// each polled through, then the zero-length DNLOAD and the manifestation.
inline void download(Bytes& b, const Bytes& image) {
  std::uint16_t block = 0;
  for (std::size_t at = 0; at < image.size(); at += 256, ++block) {
    const std::size_t n = std::min<std::size_t>(256, image.size() - at);
    class_control(b, 4, 1, false, block, Bytes(image.begin() + static_cast<long>(at),
                                               image.begin() + static_cast<long>(at + n)));
    poll_through(b);
  }
  class_control(b, 4, 1, false, block, {});  // DNLOAD zero length
  poll_through(b);
}

// A whole update of a valid image (with a power cut in its first flash
// operations: `fault`), then UPLOAD of alternate 0 (the file: 956 bytes).
inline Bytes dfu_download(bool fault) {
  Bytes b;
  op(b, UsbFuzzOp::kEnumerate);
  if (fault) {
    op(b, UsbFuzzOp::kFlashFault);
    b.push_back(1);
    b.push_back(1);
  }
  download(b, signed_image(1, 0));
  for (std::uint16_t block = 0; block < 4; ++block) class_control(b, 4, 2, true, block, {}, 256);  // UPLOAD
  if (fault) class_control(b, 4, 4, false, 0, {});  // CLRSTATUS (leaves dfuERROR)
  return b;
}

// An image signed by another key: refused at its header.
inline Bytes dfu_refused() {
  Bytes b;
  op(b, UsbFuzzOp::kEnumerate);
  const Bytes image = signed_image(1, 3, /*stranger=*/true);
  class_control(b, 4, 1, false, 0, Bytes(image.begin(), image.begin() + 256));
  poll_through(b);
  return b;
}

// An update, a reset (the self-test passes: the image runs), then UPLOAD of
// alternate 1 (the running image) and a second update into the other slot.
inline Bytes dfu_update_reset_update() {
  Bytes b;
  op(b, UsbFuzzOp::kEnumerate);
  download(b, signed_image(1, 0));
  op(b, UsbFuzzOp::kReset);
  b.push_back(1);
  op(b, UsbFuzzOp::kEnumerate);
  setup(b, 0x01, 11, 1, 4, 0);  // SET_INTERFACE(4, alt 1)
  in_tokens(b, 0x80, 1);
  class_control(b, 4, 2, true, 0, {}, 256);  // UPLOAD
  setup(b, 0x01, 11, 0, 4, 0);  // SET_INTERFACE(4, alt 0)
  in_tokens(b, 0x80, 1);
  download(b, signed_image(2, 5));
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
          {"dfu_download_power_cut.bin", dfu_download(true)},
          {"dfu_refused.bin", dfu_refused()},
          {"dfu_update_reset_update.bin", dfu_update_reset_update()}};
}

}  // namespace hadynet::usb::fuzz::seeds

#endif  // HADYNET_FUZZ_USB_FUZZ_SEEDS_H_
