// The host tools' pure parts of model updates, without a device: the model
// image file check `hadynet flash --model` makes before touching a hand
// (tools/usb/model_image_file.h), the development key it recognises, and
// the hand's configuration string as `hadynet devices` reads it
// (tools/usb/usb_inventory.h; the firmware writes it in
// firmware/usb/running_model.h).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "firmware/model_update/model_image.h"
#include "firmware/usb/running_model.h"
#include "host-sim/model_image/signing_key.h"
#include "test/usb_host/model_image_files.h"
#include "tools/usb/model_image_file.h"
#include "tools/usb/usb_inventory.h"

namespace hadynet::usb::host_testing {
namespace {

namespace mu = model_update;
namespace tu = tools::usb;
using Bytes = std::vector<std::uint8_t>;

// A header encoded by the firmware's encoder, then `payload` bytes.
Bytes image_bytes(std::uint32_t payload_length, std::size_t payload_bytes) {
  mu::ModelImageHeader h;
  h.sequence = 7;
  h.payload_length = payload_length;
  Bytes b(mu::kImageHeaderSize + payload_bytes, 0x5A);
  mu::encode_model_image_header(h, std::span<std::uint8_t, mu::kImageHeaderSize>(b.data(), mu::kImageHeaderSize));
  return b;
}

std::string refusal(Bytes bytes) {
  try {
    tu::check_model_image_bytes(std::move(bytes), "m.img");
  } catch (const tu::ModelImageFileError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(ModelImageFile, AWellFormedHeaderAndTheExactLengthAreAccepted) {
  const tu::ModelImageFile f = tu::check_model_image_bytes(image_bytes(1000, 1000), "m.img");
  EXPECT_EQ(f.header.sequence, 7u);
  EXPECT_EQ(f.header.payload_length, 1000u);
  EXPECT_EQ(f.bytes.size(), 1256u);
}

TEST(ModelImageFile, WhatIsNotAModelImageIsRefusedWithItsDefectNamed) {
  EXPECT_EQ(refusal(Bytes(100, 0)),
            "m.img: 100 bytes, shorter than a model image's 256-byte header (hadynet model-image makes images)");
  Bytes magic = image_bytes(10, 10);
  magic[0] = 'X';
  EXPECT_EQ(refusal(magic), "m.img: not a model image: not a model image (magic is not \"HYDM\") (hadynet "
                            "model-image makes images)");
  Bytes reserved = image_bytes(10, 10);
  reserved[mu::header_offset::kReserved2] = 1;
  EXPECT_EQ(refusal(reserved), "m.img: not a model image: reserved bytes not zero (hadynet model-image makes images)");
  EXPECT_EQ(refusal(image_bytes(1000, 999)),
            "m.img: 1255 bytes, but its header says 256 + 1000 = 1256 (a truncated or extended file)");
  EXPECT_EQ(refusal(image_bytes(1000, 1001)),
            "m.img: 1257 bytes, but its header says 256 + 1000 = 1256 (a truncated or extended file)");
}

TEST(ModelImageFile, TheDevelopmentKeyIsTheRepositorysPublicKey) {
  const hadynet::host::PublicKey dev = hadynet::host::read_public_key(development_key_file());
  EXPECT_EQ(tu::development_public_key(), dev);
  EXPECT_TRUE(tu::is_development_key(dev));
  hadynet::host::PublicKey other = dev;
  other[31] ^= 1;
  EXPECT_FALSE(tu::is_development_key(other));
}

TEST(ConfigurationString, TheFirmwaresTextParsesIntoVersionHashAndSource) {
  // What the firmware writes (running_model.h) is what the host reads.
  app::Text<kMaxVersionStringChars> text;
  version_string("0.1.0", RunningModel{0x3241c067dc281689ull, mu::ModelSource::kSlotB, 12}, text);
  EXPECT_STREQ(text.c_str(), "fw 0.1.0 model 3241c067dc281689 (slot B, sequence 12)");
  tu::ConfigurationString c;
  ASSERT_TRUE(tu::parse_configuration_string(text.c_str(), c));
  EXPECT_EQ(c.firmware_version, "0.1.0");
  EXPECT_EQ(c.model_hash, "3241c067dc281689");
  EXPECT_EQ(c.model_source, "slot B, sequence 12");
  version_string("0.2.0-rc1", RunningModel{0xABCull, mu::ModelSource::kFactory, 0}, text);
  ASSERT_TRUE(tu::parse_configuration_string(text.c_str(), c));
  EXPECT_EQ(c.firmware_version, "0.2.0-rc1");
  EXPECT_EQ(c.model_hash, "0000000000000abc");
  EXPECT_EQ(c.model_source, "factory");
  // An older firmware's text (no source): parsed, source empty.
  ASSERT_TRUE(tu::parse_configuration_string("fw 0.1.0 model 3241c067dc281689", c));
  EXPECT_EQ(c.model_source, "");
  for (const char* bad : {"", "fw 0.1.0", "fw  model 3241c067dc281689", "fw 0.1.0 model 3241c067dc28168",
                          "fw 0.1.0 model 3241c067dc28168x", "fw 0.1.0 model 3241c067dc281689 factory",
                          "fw 0.1.0 model 3241c067dc281689 (factory", "firmware 0.1.0 model 3241c067dc281689"}) {
    EXPECT_FALSE(tu::parse_configuration_string(bad, c)) << bad;
  }
}

}  // namespace
}  // namespace hadynet::usb::host_testing
