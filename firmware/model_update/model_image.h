// The signed model image: a 256-byte header followed by the payload (the
// model's tensors; opaque bytes here). All fields little-endian:
//
//   off size    field
//   0   u32     magic 0x4D445948 (bytes "HYDM")
//   4   u16     format version, 1
//   6   u16     header size, 256
//   8   u16     model contract version (firmware/core/model_contract.h)
//   10  u8      numeric: 0 = q15, 1 = f32
//   11  u8      flags: bit 0 = downgrade allowed (set by the signer); other bits 0
//   12  u32     sequence number, >= 1, monotonic per signer
//   16  u64     shape id (a hash of the model's compile-time shape)
//   24  u32     payload length, bytes
//   28  u32     self-test checksum (the self-test's expected output; handed to the SelfTest)
//   32  u16[8]  dims: x, u, y, pb, hidden, states, train_steps, detect_steps (information)
//   48  u8[16]  frac bits: 12 used, the last 4 zero (information)
//   64  u64     model hash, FNV-1a 64 of the model file (information)
//   72  u8[24]  reserved, zero
//   96  u8[32]  the signer's Ed25519 public key
//   128 u8[32]  SHA-256 of the payload
//   160 u8[32]  reserved, zero
//   192 u8[64]  Ed25519 signature over header bytes [0, 192)
//
// Well-formed (decode accepts): magic, version and header size as above, no
// flag bit but bit 0, every reserved byte and the 4 unused frac-bit bytes
// zero, sequence >= 1. Whether the image suits a device (identity, key,
// signature, payload hash) is image_check.h's business.
//
// Host and firmware: the image writer encodes a header with a zero
// signature, signs bytes [0, kSignedBytes) and stores the signature (or
// encodes again with it).
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_MODEL_IMAGE_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_MODEL_IMAGE_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace hadynet::model_update {

inline constexpr std::uint32_t kImageMagic = 0x4D445948u;  // "HYDM" in byte order
inline constexpr std::uint16_t kImageFormatVersion = 1;
inline constexpr std::size_t kImageHeaderSize = 256;      // bytes
inline constexpr std::size_t kSignedBytes = 192;          // the signature covers header bytes [0, 192)
inline constexpr std::size_t kPublicKeyBytes = 32;
inline constexpr std::size_t kSignatureBytes = 64;
inline constexpr std::size_t kPayloadHashBytes = 32;      // SHA-256
inline constexpr std::size_t kDimCount = 8;
inline constexpr std::size_t kFracBitsUsed = 12;

// Field offsets (bytes from the header's start).
namespace header_offset {
inline constexpr std::size_t kMagic = 0;
inline constexpr std::size_t kFormatVersion = 4;
inline constexpr std::size_t kHeaderSize = 6;
inline constexpr std::size_t kContractVersion = 8;
inline constexpr std::size_t kNumeric = 10;
inline constexpr std::size_t kFlags = 11;
inline constexpr std::size_t kSequence = 12;
inline constexpr std::size_t kShapeId = 16;
inline constexpr std::size_t kPayloadLength = 24;
inline constexpr std::size_t kSelfTestChecksum = 28;
inline constexpr std::size_t kDims = 32;
inline constexpr std::size_t kFracBits = 48;      // 16 bytes, the last 4 must be zero
inline constexpr std::size_t kModelHash = 64;
inline constexpr std::size_t kReserved1 = 72;     // 24 bytes, zero
inline constexpr std::size_t kPublicKey = 96;
inline constexpr std::size_t kPayloadSha256 = 128;
inline constexpr std::size_t kReserved2 = 160;    // 32 bytes, zero
inline constexpr std::size_t kSignature = 192;
}  // namespace header_offset

inline constexpr std::uint8_t kFlagDowngradeAllowed = 0x01;  // the only defined flag bit

// The header's `numeric` byte.
inline constexpr std::uint8_t kNumericQ15 = 0;
inline constexpr std::uint8_t kNumericF32 = 1;

// Indices into ModelImageHeader::dims.
enum ImageDim : std::size_t {
  kDimX = 0, kDimU, kDimY, kDimPb, kDimHidden, kDimStates, kDimTrainSteps, kDimDetectSteps,
};

// A decoded header. Magic, format version and header size are constants,
// not fields: decode checks them and encode writes them.
struct ModelImageHeader {
  std::uint16_t contract_version = 0;
  std::uint8_t numeric = kNumericQ15;
  bool downgrade_allowed = false;  // flags bit 0
  std::uint32_t sequence = 0;      // >= 1
  std::uint64_t shape_id = 0;
  std::uint32_t payload_length = 0;  // bytes
  std::uint32_t self_test_checksum = 0;
  std::array<std::uint16_t, kDimCount> dims{};
  std::array<std::uint8_t, kFracBitsUsed> frac_bits{};
  std::uint64_t model_hash = 0;
  std::array<std::uint8_t, kPublicKeyBytes> public_key{};
  std::array<std::uint8_t, kPayloadHashBytes> payload_sha256{};
  std::array<std::uint8_t, kSignatureBytes> signature{};

  friend bool operator==(const ModelImageHeader&, const ModelImageHeader&) = default;
};

// Why a header is not well-formed (the first defect found, in this order).
enum class HeaderFormat : std::uint8_t {
  kWellFormed = 0,
  kBadMagic,
  kBadFormatVersion,
  kBadHeaderSize,
  kUnknownFlags,      // a flag bit other than bit 0
  kReservedNotZero,   // reserved bytes or the 4 unused frac-bit bytes
  kZeroSequence,
};

// A short English description ("reserved bytes not zero"), never null.
const char* header_format_text(HeaderFormat f) noexcept;

// Writes the 256 header bytes (reserved bytes zero).
void encode_model_image_header(const ModelImageHeader& header,
                               std::span<std::uint8_t, kImageHeaderSize> out) noexcept;

// Reads the 256 header bytes into `out` (completely written when the result
// is kWellFormed, unspecified otherwise).
HeaderFormat decode_model_image_header(std::span<const std::uint8_t, kImageHeaderSize> bytes,
                                       ModelImageHeader& out) noexcept;

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_MODEL_IMAGE_H_
