// One byte stream of the link (a UART, a USB CDC-ACM data interface) into a
// LinkDispatcher that may serve several streams: the stream's own COBS
// decoder and reply buffers, and a reference to the shared dispatcher (the
// runtime, the autonomous loop and the sequence expectation). Two ports on
// one dispatcher never mix bytes of their frames; they share one device
// state, so one host session at a time (a host starts with a reset, which
// any port accepts with any sequence number).
#ifndef HADYNET_FIRMWARE_LINK_LINK_PORT_H_
#define HADYNET_FIRMWARE_LINK_LINK_PORT_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/core/model_contract.h"
#include "firmware/link/dispatcher.h"
#include "firmware/link/frame.h"
#include "firmware/link/stream_decoder.h"

namespace hadynet::link {

template <firmware::GeneratedModel M>
class LinkPort {
 public:
  // `dispatcher` must outlive the port.
  explicit LinkPort(LinkDispatcher<M>& dispatcher) noexcept : dispatcher_(dispatcher) {}

  LinkPort(const LinkPort&) = delete;
  LinkPort& operator=(const LinkPort&) = delete;

  // Feeds one received byte. Returns the wire bytes of the reply to send
  // (COBS + 0x00), or an empty span; valid until the next call on this
  // port. At most one reply per received frame (and one per oversize frame).
  std::span<const std::uint8_t> receive(std::uint8_t byte) noexcept {
    std::size_t reply_size = 0;
    switch (decoder_.push(byte)) {
      case StreamDecoder::Event::kNone:
        return {};
      case StreamDecoder::Event::kFrame:
        reply_size = dispatcher_.handle(decoder_.frame(), reply_);
        break;
      case StreamDecoder::Event::kOversize:
        reply_size = dispatcher_.stream_error(ErrorCode::kOversize, "frame exceeds 512 encoded bytes", reply_);
        break;
      case StreamDecoder::Event::kBadEncoding:
        reply_size = dispatcher_.stream_error(ErrorCode::kTruncated, "COBS block cut short", reply_);
        break;
    }
    const std::size_t n = encode_for_wire(std::span<const std::uint8_t>(reply_).first(reply_size), wire_);
    return std::span<const std::uint8_t>(wire_).first(n);
  }

  const StreamDecoder& decoder() const noexcept { return decoder_; }

 private:
  static_assert(kMaxEncodedFrame == 512, "update the oversize reason text");

  LinkDispatcher<M>& dispatcher_;
  StreamDecoder decoder_{};
  std::uint8_t reply_[kMaxFrame] = {};
  std::uint8_t wire_[kMaxWireFrame] = {};
};

}  // namespace hadynet::link

#endif  // HADYNET_FIRMWARE_LINK_LINK_PORT_H_
