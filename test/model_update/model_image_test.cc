// The image header format (firmware/model_update/model_image.h): the exact
// byte layout, round trip, every malformation, and the signature as
// libsodium sees it.
#include <gtest/gtest.h>
#include <sodium.h>

#include <array>

#include "firmware/model_update/model_image.h"
#include "test/model_update/signed_images.h"
#include "test/model_update/slot_test_device.h"

namespace hadynet::model_update::test {
namespace {

using HeaderBytes = std::array<std::uint8_t, kImageHeaderSize>;

ModelImageHeader sample_header() {
  ModelImageHeader h = header_for(small_identity(), 0x01020304u);
  h.downgrade_allowed = true;
  h.numeric = kNumericF32;
  for (std::size_t i = 0; i < h.public_key.size(); ++i) h.public_key[i] = static_cast<std::uint8_t>(0xA0 + i);
  for (std::size_t i = 0; i < h.payload_sha256.size(); ++i) h.payload_sha256[i] = static_cast<std::uint8_t>(0x40 + i);
  for (std::size_t i = 0; i < h.signature.size(); ++i) h.signature[i] = static_cast<std::uint8_t>(0x80 + i);
  return h;
}

HeaderBytes encoded(const ModelImageHeader& h) {
  HeaderBytes b{};
  encode_model_image_header(h, b);
  return b;
}

TEST(ModelImageFormat, EncodesTheDocumentedLittleEndianLayout) {
  const ModelImageHeader h = sample_header();
  const HeaderBytes b = encoded(h);
  EXPECT_EQ(b[0], 'H');
  EXPECT_EQ(b[1], 'Y');
  EXPECT_EQ(b[2], 'D');
  EXPECT_EQ(b[3], 'M');
  EXPECT_EQ(b[4], 1);  // format version 1
  EXPECT_EQ(b[5], 0);
  EXPECT_EQ(b[6], 0x00);  // header size 256
  EXPECT_EQ(b[7], 0x01);
  EXPECT_EQ(b[8], 3);  // contract version
  EXPECT_EQ(b[9], 0);
  EXPECT_EQ(b[10], 1);  // f32
  EXPECT_EQ(b[11], 1);  // downgrade allowed
  EXPECT_EQ((std::array<std::uint8_t, 4>{b[12], b[13], b[14], b[15]}), (std::array<std::uint8_t, 4>{4, 3, 2, 1}));
  EXPECT_EQ(b[16], 0x11);  // shape id 0x5EED5EEDF00DBA11, least significant byte first
  EXPECT_EQ(b[23], 0x5E);
  EXPECT_EQ(b[24], 6000 & 0xFF);
  EXPECT_EQ(b[25], 6000 >> 8);
  EXPECT_EQ(b[28], (0xC0FFEE00u + 0x01020304u) & 0xFF);
  EXPECT_EQ(b[32], 18);  // dims[0] = x
  EXPECT_EQ(b[32 + 2 * kDimHidden], 64);
  EXPECT_EQ(b[48], 8);  // frac bits
  EXPECT_EQ(b[59], 19);
  for (std::size_t i = 60; i < 64; ++i) EXPECT_EQ(b[i], 0) << i;
  EXPECT_EQ(b[64], static_cast<std::uint8_t>(0x25 ^ 0x04));  // model hash, low byte
  for (std::size_t i = 72; i < 96; ++i) EXPECT_EQ(b[i], 0) << i;
  EXPECT_EQ(b[96], 0xA0);
  EXPECT_EQ(b[127], 0xA0 + 31);
  EXPECT_EQ(b[128], 0x40);
  EXPECT_EQ(b[159], 0x40 + 31);
  for (std::size_t i = 160; i < 192; ++i) EXPECT_EQ(b[i], 0) << i;
  EXPECT_EQ(b[192], 0x80);
  EXPECT_EQ(b[255], 0x80 + 63);
}

TEST(ModelImageFormat, DecodeInvertsEncode) {
  const ModelImageHeader h = sample_header();
  ModelImageHeader back;
  ASSERT_EQ(decode_model_image_header(encoded(h), back), HeaderFormat::kWellFormed);
  EXPECT_EQ(back, h);
}

TEST(ModelImageFormat, RefusesEveryMalformation) {
  const HeaderBytes good = encoded(sample_header());
  const auto decode_with = [&](std::size_t offset, std::uint8_t value) {
    HeaderBytes b = good;
    b[offset] = value;
    ModelImageHeader h;
    return decode_model_image_header(b, h);
  };
  EXPECT_EQ(decode_with(0, 'h'), HeaderFormat::kBadMagic);
  EXPECT_EQ(decode_with(4, 2), HeaderFormat::kBadFormatVersion);
  EXPECT_EQ(decode_with(6, 0x80), HeaderFormat::kBadHeaderSize);
  for (int bit = 1; bit < 8; ++bit) {
    EXPECT_EQ(decode_with(11, static_cast<std::uint8_t>(1u << bit)), HeaderFormat::kUnknownFlags) << bit;
  }
  for (std::size_t i = 60; i < 64; ++i) EXPECT_EQ(decode_with(i, 1), HeaderFormat::kReservedNotZero) << i;
  for (std::size_t i = 72; i < 96; ++i) EXPECT_EQ(decode_with(i, 0x40), HeaderFormat::kReservedNotZero) << i;
  for (std::size_t i = 160; i < 192; ++i) EXPECT_EQ(decode_with(i, 0x01), HeaderFormat::kReservedNotZero) << i;
  HeaderBytes zero_sequence = good;
  for (std::size_t i = 12; i < 16; ++i) zero_sequence[i] = 0;
  ModelImageHeader h;
  EXPECT_EQ(decode_model_image_header(zero_sequence, h), HeaderFormat::kZeroSequence);
  HeaderBytes erased{};
  erased.fill(0xFF);
  EXPECT_EQ(decode_model_image_header(erased, h), HeaderFormat::kBadMagic);
  EXPECT_STREQ(header_format_text(HeaderFormat::kReservedNotZero), "reserved bytes not zero");
}

TEST(ModelImageFormat, SignatureCoversTheFirst192BytesAsLibsodiumChecks) {
  const Bytes image = small_image(7, 70);
  const std::span<const std::uint8_t> head = header_of(image);
  ModelImageHeader h;
  ASSERT_EQ(decode_model_image_header(head.first<kImageHeaderSize>(), h), HeaderFormat::kWellFormed);
  EXPECT_EQ(h.public_key, device_key().public_key);
  EXPECT_EQ(h.sequence, 7u);
  EXPECT_EQ(h.payload_length, 6000u);
  EXPECT_EQ(crypto_sign_verify_detached(h.signature.data(), head.data(), kSignedBytes, h.public_key.data()), 0);
  std::array<std::uint8_t, 32> digest{};
  crypto_hash_sha256(digest.data(), payload_of(image).data(), payload_of(image).size());
  EXPECT_EQ(digest, h.payload_sha256);
}

}  // namespace
}  // namespace hadynet::model_update::test
