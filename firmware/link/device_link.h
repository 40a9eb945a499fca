// The whole device end of the link as pure code: received bytes in, bytes to
// transmit out. StreamDecoder (COBS, hard size limit) feeds LinkDispatcher;
// each reply is COBS-encoded and delimited. A board's transport calls
// receive() for every byte from its UART and sends what it returns. All
// buffers are members, sized at compile time (about 1.5 KiB, plus the
// autonomous loop's state, ~0.5 KiB for the hand's model).
#ifndef HADYNET_FIRMWARE_LINK_DEVICE_LINK_H_
#define HADYNET_FIRMWARE_LINK_DEVICE_LINK_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_contract.h"
#include "firmware/link/dispatcher.h"
#include "firmware/link/frame.h"
#include "firmware/link/stream_decoder.h"

namespace hadynet::link {

template <firmware::GeneratedModel M>
class DeviceLink {
 public:
  explicit DeviceLink(firmware::HadynetRuntime<M>& runtime) noexcept : dispatcher_(runtime) {}

  // Feeds one received byte. Returns the wire bytes of the reply to send
  // (COBS + 0x00), or an empty span; valid until the next call. At most one
  // reply per received frame (and one per oversize frame).
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

  const LinkDispatcher<M>& dispatcher() const noexcept { return dispatcher_; }
  // The autonomous 5 Hz loop the link feeds (firmware/app/period_loop.h).
  app::PeriodLoop<M>& loop() noexcept { return dispatcher_.loop(); }
  const app::PeriodLoop<M>& loop() const noexcept { return dispatcher_.loop(); }
  const StreamDecoder& decoder() const noexcept { return decoder_; }

 private:
  static_assert(kMaxEncodedFrame == 512, "update the oversize reason text");

  StreamDecoder decoder_{};
  LinkDispatcher<M> dispatcher_;
  std::uint8_t reply_[kMaxFrame] = {};
  std::uint8_t wire_[kMaxWireFrame] = {};
};

}  // namespace hadynet::link

#endif  // HADYNET_FIRMWARE_LINK_DEVICE_LINK_H_
