// Byte-at-a-time receiver of COBS frames (docs/protocol.md, "Transport").
// Decodes while it receives, into one fixed buffer; never holds more than
// kMaxEncodedFrame encoded bytes of one frame. Per 0x00 delimiter it reports
// a complete decoded frame, or an error; empty frames (consecutive or leading
// delimiters) are ignored. A frame that grows past kMaxEncodedFrame is
// reported as oversize once, at its (kMaxEncodedFrame + 1)-th byte, and
// everything up to the next delimiter is dropped. Pure code, no I/O.
#ifndef HADYNET_FIRMWARE_LINK_STREAM_DECODER_H_
#define HADYNET_FIRMWARE_LINK_STREAM_DECODER_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/link/cobs.h"
#include "firmware/link/frame.h"

namespace hadynet::link {

class StreamDecoder {
 public:
  enum class Event : std::uint8_t {
    kNone = 0,    // nothing complete yet (or an empty frame was skipped)
    kFrame,       // frame() holds a complete decoded frame
    kOversize,    // the current frame exceeded kMaxEncodedFrame; dropping to the next delimiter
    kBadEncoding  // the frame ended inside a COBS block (truncated encoding)
  };

  // Feeds one received byte.
  constexpr Event push(std::uint8_t byte) noexcept {
    if (byte == 0) {
      const bool was_dropping = dropping_;
      const std::size_t count = encoded_count_;
      const CobsDecodeState state = cobs_;
      start_frame();
      if (was_dropping || count == 0) return Event::kNone;
      if (cobs_decode_finish(state) != CobsStatus::kOk) return Event::kBadEncoding;
      frame_size_ = state.size;
      return Event::kFrame;
    }
    if (dropping_) return Event::kNone;
    if (encoded_count_ == kMaxEncodedFrame) {
      dropping_ = true;
      return Event::kOversize;
    }
    ++encoded_count_;
    // Decoded data is always shorter than its encoding, so the buffer
    // (kMaxEncodedFrame bytes) cannot fill; the check stays as a guard.
    if (cobs_decode_byte(cobs_, byte, buffer_) != CobsStatus::kOk) {
      dropping_ = true;
      return Event::kOversize;
    }
    return Event::kNone;
  }

  // The frame of the last kFrame event; valid until the next push().
  constexpr std::span<const std::uint8_t> frame() const noexcept {
    return std::span<const std::uint8_t>(buffer_).first(frame_size_);
  }

  // Forgets any partial frame (the next byte starts a new frame).
  constexpr void clear() noexcept { start_frame(); }

  // Encoded bytes of the current partial frame (0 between frames).
  constexpr std::size_t pending() const noexcept { return encoded_count_; }
  constexpr bool dropping() const noexcept { return dropping_; }

 private:
  constexpr void start_frame() noexcept {
    cobs_ = CobsDecodeState{};
    encoded_count_ = 0;
    dropping_ = false;
    frame_size_ = 0;
  }

  CobsDecodeState cobs_{};
  std::size_t encoded_count_ = 0;
  bool dropping_ = false;
  std::size_t frame_size_ = 0;
  std::uint8_t buffer_[kMaxEncodedFrame] = {};
};

}  // namespace hadynet::link

#endif  // HADYNET_FIRMWARE_LINK_STREAM_DECODER_H_
