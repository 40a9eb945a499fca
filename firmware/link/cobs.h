// Consistent Overhead Byte Stuffing (Cheshire & Baker, 1999): the link's
// transport encoding (docs/protocol.md). An encoded frame contains no 0x00
// byte, so 0x00 delimits frames on the wire.
//
// Encoding: the data, with a zero appended conceptually, is cut at its zeros
// into blocks; each block is sent as a code byte (block length + 1, 1..255)
// followed by its non-zero bytes. Code 0xFF marks a block of 254 non-zero
// bytes that is NOT followed by a zero. n bytes encode into at most
// n + n/254 + 1 bytes (cobs_max_encoded_size); never into 0 bytes.
//
// All functions write into caller buffers and check every write against the
// buffer's size; none allocates. The incremental decoder (CobsDecodeState)
// is what the byte-at-a-time stream decoder uses.
#ifndef HADYNET_FIRMWARE_LINK_COBS_H_
#define HADYNET_FIRMWARE_LINK_COBS_H_

#include <cstddef>
#include <cstdint>
#include <span>

namespace hadynet::link {

// Largest encoding of n data bytes.
constexpr std::size_t cobs_max_encoded_size(std::size_t n) noexcept { return n + n / 254 + 1; }

// Encodes `in` into `out` (no delimiter). Returns the encoded size (>= 1), or
// 0 if `out` is too small (its contents are then unspecified).
constexpr std::size_t cobs_encode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept {
  if (out.empty()) return 0;
  std::size_t code_pos = 0;  // where the current block's code byte goes
  std::size_t pos = 1;       // next free output byte
  std::uint8_t code = 1;     // current block length + 1
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] != 0) {
      if (pos >= out.size()) return 0;
      out[pos++] = in[i];
      ++code;
      // A full block (254 bytes) closes without an implied zero; a new block
      // starts only if data follows, so a trailing full block ends the frame.
      if (code == 0xFF && i + 1 < in.size()) {
        if (pos >= out.size()) return 0;
        out[code_pos] = code;
        code_pos = pos++;
        code = 1;
      }
    } else {
      if (pos >= out.size()) return 0;
      out[code_pos] = code;
      code_pos = pos++;
      code = 1;
    }
  }
  out[code_pos] = code;
  return pos;
}

enum class CobsStatus : std::uint8_t {
  kOk = 0,
  kOutputFull,   // the decoded data would not fit the output buffer
  kZeroInInput,  // a 0x00 byte inside an encoded frame
  kTruncated,    // the last block is shorter than its code byte says, or no input
};

// Incremental decoder: feed the encoded bytes of one frame one at a time with
// cobs_decode_byte, then call cobs_decode_finish at the frame's delimiter.
// Decoded bytes go to out[0 .. size). A default-constructed state starts a frame.
struct CobsDecodeState {
  std::uint8_t code = 0;  // code byte of the current block; 0: no block yet
  std::uint8_t left = 0;  // data bytes still to come in the current block
  std::size_t size = 0;   // decoded bytes written so far
};

constexpr CobsStatus cobs_decode_byte(CobsDecodeState& s, std::uint8_t byte, std::span<std::uint8_t> out) noexcept {
  if (byte == 0) return CobsStatus::kZeroInInput;
  if (s.left == 0) {
    // A code byte. The previous block implied a zero unless it was full
    // (0xFF); the implied zero after the frame's last block is not data, so
    // it is written only here, when another block follows.
    if (s.code != 0 && s.code != 0xFF) {
      if (s.size >= out.size()) return CobsStatus::kOutputFull;
      out[s.size++] = 0;
    }
    s.code = byte;
    s.left = static_cast<std::uint8_t>(byte - 1);
    return CobsStatus::kOk;
  }
  if (s.size >= out.size()) return CobsStatus::kOutputFull;
  out[s.size++] = byte;
  --s.left;
  return CobsStatus::kOk;
}

// At the delimiter: kOk if the frame ended on a block boundary (decoded size
// in s.size), kTruncated otherwise (including a frame with no bytes).
constexpr CobsStatus cobs_decode_finish(const CobsDecodeState& s) noexcept {
  if (s.code == 0 || s.left != 0) return CobsStatus::kTruncated;
  return CobsStatus::kOk;
}

struct CobsDecodeResult {
  CobsStatus status = CobsStatus::kOk;
  std::size_t size = 0;  // decoded bytes (valid when status is kOk)
};

// Decodes one whole encoded frame (without its delimiter) into `out`.
constexpr CobsDecodeResult cobs_decode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept {
  CobsDecodeState s;
  for (const std::uint8_t b : in) {
    const CobsStatus st = cobs_decode_byte(s, b, out);
    if (st != CobsStatus::kOk) return {st, 0};
  }
  const CobsStatus st = cobs_decode_finish(s);
  return {st, st == CobsStatus::kOk ? s.size : 0};
}

}  // namespace hadynet::link

#endif  // HADYNET_FIRMWARE_LINK_COBS_H_
