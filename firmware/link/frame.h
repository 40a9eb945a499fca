// The link's frames, decoded (docs/protocol.md, version 1):
//
//   offset  size  field
//   0       1     version (kProtocolVersion)
//   1       1     type (MessageType)
//   2       2     sequence number, u16 LE
//   4       2     payload length n, u16 LE
//   6       n     payload
//   6 + n   4     CRC-32 (crc32.h) of bytes [0, 6 + n), u32 LE
//
// All multi-byte fields little-endian, floats IEEE binary32 LE. On the wire a
// frame is COBS-encoded (cobs.h) and followed by one 0x00 delimiter.
// Everything here is pure, bounded and allocation-free; firmware and host
// tools share it.
#ifndef HADYNET_FIRMWARE_LINK_FRAME_H_
#define HADYNET_FIRMWARE_LINK_FRAME_H_

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/link/cobs.h"
#include "firmware/link/crc32.h"

namespace hadynet::link {

inline constexpr std::uint8_t kProtocolVersion = 1;

inline constexpr std::size_t kHeaderSize = 6;
inline constexpr std::size_t kCrcSize = 4;
inline constexpr std::size_t kFrameOverhead = kHeaderSize + kCrcSize;
// Hard limit on one encoded frame on the wire (COBS bytes, without the
// delimiter). A receiver drops longer frames unbuffered ("oversize").
inline constexpr std::size_t kMaxEncodedFrame = 512;
// Largest payload and decoded frame a sender may send; its worst-case COBS
// encoding fits kMaxEncodedFrame.
inline constexpr std::size_t kMaxPayload = 490;
inline constexpr std::size_t kMaxFrame = kFrameOverhead + kMaxPayload;
// A frame on the wire: encoding plus delimiter.
inline constexpr std::size_t kMaxWireFrame = kMaxEncodedFrame + 1;
static_assert(cobs_max_encoded_size(kMaxFrame) <= kMaxEncodedFrame);

enum class MessageType : std::uint8_t {
  kInfoRequest = 0x01,
  kSensorFrame = 0x02,
  kSetPb = 0x03,
  kSetMode = 0x04,
  kReset = 0x05,
  kMuscleState = 0x06,         // the host's half of the autonomous loop's frame
  kTare = 0x07,                // loadcell offsets
  kPeriodResultRequest = 0x08,  // the autonomous loop's latest period record
  kAdapt = 0x09,                // PB adaptation on/off/adopt, its status
  kError = 0x7F,  // reply to any request that was not executed
  kInfo = 0x81,
  kStepResult = 0x82,
  kSetPbAck = 0x83,
  kSetModeAck = 0x84,
  kResetAck = 0x85,
  kMuscleStateAck = 0x86,
  kTareAck = 0x87,
  kPeriodResult = 0x88,
  kAdaptStatus = 0x89,
};
inline constexpr std::uint8_t kReplyBit = 0x80;  // reply type = request type | kReplyBit

constexpr bool is_request_type(std::uint8_t type) noexcept {
  return type >= static_cast<std::uint8_t>(MessageType::kInfoRequest) &&
         type <= static_cast<std::uint8_t>(MessageType::kAdapt);
}
constexpr MessageType reply_type_of(MessageType request) noexcept {
  return static_cast<MessageType>(static_cast<std::uint8_t>(request) | kReplyBit);
}

// Error reply codes (wire values). 0 is not a code: "no error".
enum class ErrorCode : std::uint8_t {
  kNone = 0,
  kBadCrc = 1,            // CRC-32 mismatch
  kTruncated = 2,         // shorter than its header or length field says; or a COBS block cut short
  kOversize = 3,          // more than kMaxEncodedFrame encoded bytes before a delimiter
  kUnknownType = 4,       // not a request type
  kBadVersion = 5,        // version byte is not kProtocolVersion
  kBadPayloadLength = 6,  // longer than its length field says, or the wrong payload size for its type
  kBadValue = 7,          // a payload field out of range (PB state, non-finite PB, mode, PB kind)
  kOutOfOrder = 8,        // sequence number is not the expected one
  kNotReady = 9,          // well-formed, but the device cannot do it yet (tare before any loadcell reading)
};

// ---- little-endian field access with bounds checks

// Appends fields to a buffer; a write past the end sets !ok() and is dropped.
class ByteWriter {
 public:
  constexpr explicit ByteWriter(std::span<std::uint8_t> out) noexcept : out_(out) {}

  constexpr void u8(std::uint8_t v) noexcept {
    if (pos_ >= out_.size()) {
      ok_ = false;
      return;
    }
    out_[pos_++] = v;
  }
  constexpr void u16(std::uint16_t v) noexcept {
    u8(static_cast<std::uint8_t>(v));
    u8(static_cast<std::uint8_t>(v >> 8));
  }
  constexpr void u32(std::uint32_t v) noexcept {
    u16(static_cast<std::uint16_t>(v));
    u16(static_cast<std::uint16_t>(v >> 16));
  }
  constexpr void u64(std::uint64_t v) noexcept {
    u32(static_cast<std::uint32_t>(v));
    u32(static_cast<std::uint32_t>(v >> 32));
  }
  constexpr void f32(float v) noexcept { u32(std::bit_cast<std::uint32_t>(v)); }

  constexpr std::size_t size() const noexcept { return pos_; }
  constexpr bool ok() const noexcept { return ok_; }

 private:
  std::span<std::uint8_t> out_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

// Reads fields from a buffer; a read past the end returns 0 and sets !ok().
class ByteReader {
 public:
  constexpr explicit ByteReader(std::span<const std::uint8_t> in) noexcept : in_(in) {}

  constexpr std::uint8_t u8() noexcept {
    if (pos_ >= in_.size()) {
      ok_ = false;
      return 0;
    }
    return in_[pos_++];
  }
  constexpr std::uint16_t u16() noexcept {
    const std::uint16_t lo = u8();
    return static_cast<std::uint16_t>(lo | (u8() << 8));
  }
  constexpr std::uint32_t u32() noexcept {
    const std::uint32_t lo = u16();
    return lo | (static_cast<std::uint32_t>(u16()) << 16);
  }
  constexpr std::uint64_t u64() noexcept {
    const std::uint64_t lo = u32();
    return lo | (static_cast<std::uint64_t>(u32()) << 32);
  }
  constexpr float f32() noexcept { return std::bit_cast<float>(u32()); }

  constexpr std::size_t remaining() const noexcept { return in_.size() - pos_; }
  constexpr bool ok() const noexcept { return ok_; }

 private:
  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

// ---- parsing

struct Frame {
  std::uint8_t version = 0;
  std::uint8_t type = 0;
  std::uint16_t sequence = 0;  // 0 unless the CRC checked (see parse_frame)
  std::span<const std::uint8_t> payload;
};

// Outcome of a check: ok, or an error code with a static ASCII reason (the
// error reply's text).
struct Status {
  ErrorCode code = ErrorCode::kNone;
  const char* reason = "";
  constexpr bool ok() const noexcept { return code == ErrorCode::kNone; }
};

// Checks one decoded frame, in this order: size against the header and the
// length field (kTruncated / kBadPayloadLength), CRC (kBadCrc), version
// (kBadVersion). The header fields of `out` are filled only once the CRC has
// checked, so a frame rejected before that reports sequence number 0; a frame
// with a bad version still carries its sequence number. The payload span
// points into `in`. The type is not checked here.
constexpr Status parse_frame(std::span<const std::uint8_t> in, Frame& out) noexcept {
  out = Frame{};
  if (in.size() < kFrameOverhead) return {ErrorCode::kTruncated, "frame shorter than header and CRC"};
  const std::size_t length = static_cast<std::size_t>(in[4]) | (static_cast<std::size_t>(in[5]) << 8);
  if (in.size() < kFrameOverhead + length) return {ErrorCode::kTruncated, "frame shorter than its length field says"};
  if (in.size() > kFrameOverhead + length) {
    return {ErrorCode::kBadPayloadLength, "frame longer than its length field says"};
  }
  ByteReader crc_field(in.subspan(kHeaderSize + length, kCrcSize));
  if (crc_field.u32() != crc32(in.first(kHeaderSize + length))) return {ErrorCode::kBadCrc, "CRC mismatch"};
  out.version = in[0];
  out.type = in[1];
  out.sequence = static_cast<std::uint16_t>(in[2] | (in[3] << 8));
  out.payload = in.subspan(kHeaderSize, length);
  if (out.version != kProtocolVersion) return {ErrorCode::kBadVersion, "unsupported protocol version"};
  return {};
}

// ---- building

// Builds one frame in `out`: the caller writes the payload into payload(),
// then finish() writes header and CRC and returns the frame's size (0 if the
// payload does not fit `out` or exceeds kMaxPayload).
class FrameBuilder {
 public:
  constexpr explicit FrameBuilder(std::span<std::uint8_t> out) noexcept : out_(out) {}

  constexpr std::span<std::uint8_t> payload() const noexcept {
    if (out_.size() < kFrameOverhead) return {};
    const std::size_t room = out_.size() - kFrameOverhead;
    return out_.subspan(kHeaderSize, room < kMaxPayload ? room : kMaxPayload);
  }

  constexpr std::size_t finish(MessageType type, std::uint16_t sequence, std::size_t payload_size) noexcept {
    return finish_raw(kProtocolVersion, static_cast<std::uint8_t>(type), sequence, payload_size);
  }
  // Any version and type byte (tests and tools that build invalid frames).
  constexpr std::size_t finish_raw(std::uint8_t version, std::uint8_t type, std::uint16_t sequence,
                                   std::size_t payload_size) noexcept {
    if (out_.size() < kFrameOverhead || payload_size > payload().size()) return 0;
    ByteWriter header(out_.first(kHeaderSize));
    header.u8(version);
    header.u8(type);
    header.u16(sequence);
    header.u16(static_cast<std::uint16_t>(payload_size));
    const std::size_t body = kHeaderSize + payload_size;
    ByteWriter crc_field(out_.subspan(body, kCrcSize));
    crc_field.u32(crc32(out_.first(body)));
    return body + kCrcSize;
  }

 private:
  std::span<std::uint8_t> out_;
};

// COBS-encodes a decoded frame and appends the delimiter: the bytes to send.
// Returns the wire size, 0 if `wire` is too small.
constexpr std::size_t encode_for_wire(std::span<const std::uint8_t> frame, std::span<std::uint8_t> wire) noexcept {
  if (wire.empty()) return 0;
  const std::size_t n = cobs_encode(frame, wire.first(wire.size() - 1));
  if (n == 0) return 0;
  wire[n] = 0;
  return n + 1;
}

}  // namespace hadynet::link

#endif  // HADYNET_FIRMWARE_LINK_FRAME_H_
