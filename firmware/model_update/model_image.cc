#include "firmware/model_update/model_image.h"

#include <algorithm>

#include "firmware/core/little_endian.h"

namespace hadynet::model_update {

using firmware::get_le16;
using firmware::get_le32;
using firmware::get_le64;
using firmware::put_le16;
using firmware::put_le32;
using firmware::put_le64;

namespace {

namespace off = header_offset;

constexpr std::size_t kReserved1Bytes = off::kPublicKey - off::kReserved1;
constexpr std::size_t kReserved2Bytes = off::kSignature - off::kReserved2;
constexpr std::size_t kFracBitsField = off::kModelHash - off::kFracBits;
static_assert(kReserved1Bytes == 24 && kReserved2Bytes == 32 && kFracBitsField == 16);
static_assert(off::kSignature + kSignatureBytes == kImageHeaderSize && off::kSignature == kSignedBytes);

bool all_zero(std::span<const std::uint8_t> bytes) noexcept {
  return std::all_of(bytes.begin(), bytes.end(), [](std::uint8_t b) { return b == 0; });
}

}  // namespace

const char* header_format_text(HeaderFormat f) noexcept {
  switch (f) {
    case HeaderFormat::kWellFormed: return "well-formed";
    case HeaderFormat::kBadMagic: return "not a model image (magic is not \"HYDM\")";
    case HeaderFormat::kBadFormatVersion: return "unknown image format version";
    case HeaderFormat::kBadHeaderSize: return "header size is not 256";
    case HeaderFormat::kUnknownFlags: return "unknown flag bits set";
    case HeaderFormat::kReservedNotZero: return "reserved bytes not zero";
    case HeaderFormat::kZeroSequence: return "sequence number 0";
  }
  return "unknown header defect";
}

void encode_model_image_header(const ModelImageHeader& h, std::span<std::uint8_t, kImageHeaderSize> out) noexcept {
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  std::uint8_t* p = out.data();
  put_le32(p + off::kMagic, kImageMagic);
  put_le16(p + off::kFormatVersion, kImageFormatVersion);
  put_le16(p + off::kHeaderSize, static_cast<std::uint16_t>(kImageHeaderSize));
  put_le16(p + off::kContractVersion, h.contract_version);
  p[off::kNumeric] = h.numeric;
  p[off::kFlags] = h.downgrade_allowed ? kFlagDowngradeAllowed : std::uint8_t{0};
  put_le32(p + off::kSequence, h.sequence);
  put_le64(p + off::kShapeId, h.shape_id);
  put_le32(p + off::kPayloadLength, h.payload_length);
  put_le32(p + off::kSelfTestChecksum, h.self_test_checksum);
  for (std::size_t i = 0; i < kDimCount; ++i) put_le16(p + off::kDims + 2 * i, h.dims[i]);
  std::copy(h.frac_bits.begin(), h.frac_bits.end(), p + off::kFracBits);
  put_le64(p + off::kModelHash, h.model_hash);
  std::copy(h.public_key.begin(), h.public_key.end(), p + off::kPublicKey);
  std::copy(h.payload_sha256.begin(), h.payload_sha256.end(), p + off::kPayloadSha256);
  std::copy(h.signature.begin(), h.signature.end(), p + off::kSignature);
}

HeaderFormat decode_model_image_header(std::span<const std::uint8_t, kImageHeaderSize> bytes,
                                       ModelImageHeader& h) noexcept {
  const std::uint8_t* p = bytes.data();
  if (get_le32(p + off::kMagic) != kImageMagic) return HeaderFormat::kBadMagic;
  if (get_le16(p + off::kFormatVersion) != kImageFormatVersion) return HeaderFormat::kBadFormatVersion;
  if (get_le16(p + off::kHeaderSize) != kImageHeaderSize) return HeaderFormat::kBadHeaderSize;
  const std::uint8_t flags = p[off::kFlags];
  if ((flags & static_cast<std::uint8_t>(~kFlagDowngradeAllowed)) != 0) return HeaderFormat::kUnknownFlags;
  if (!all_zero(bytes.subspan(off::kReserved1, kReserved1Bytes)) ||
      !all_zero(bytes.subspan(off::kReserved2, kReserved2Bytes)) ||
      !all_zero(bytes.subspan(off::kFracBits + kFracBitsUsed, kFracBitsField - kFracBitsUsed))) {
    return HeaderFormat::kReservedNotZero;
  }
  h.contract_version = get_le16(p + off::kContractVersion);
  h.numeric = p[off::kNumeric];
  h.downgrade_allowed = (flags & kFlagDowngradeAllowed) != 0;
  h.sequence = get_le32(p + off::kSequence);
  h.shape_id = get_le64(p + off::kShapeId);
  h.payload_length = get_le32(p + off::kPayloadLength);
  h.self_test_checksum = get_le32(p + off::kSelfTestChecksum);
  for (std::size_t i = 0; i < kDimCount; ++i) h.dims[i] = get_le16(p + off::kDims + 2 * i);
  std::copy_n(p + off::kFracBits, kFracBitsUsed, h.frac_bits.begin());
  h.model_hash = get_le64(p + off::kModelHash);
  std::copy_n(p + off::kPublicKey, kPublicKeyBytes, h.public_key.begin());
  std::copy_n(p + off::kPayloadSha256, kPayloadHashBytes, h.payload_sha256.begin());
  std::copy_n(p + off::kSignature, kSignatureBytes, h.signature.begin());
  if (h.sequence == 0) return HeaderFormat::kZeroSequence;
  return HeaderFormat::kWellFormed;
}

}  // namespace hadynet::model_update
