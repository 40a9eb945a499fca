// The host end of the link protocol (docs/protocol.md) as pure code: builds
// numbered request frames ready for the wire and checks reply frames. Host
// tools (and tests) move the bytes; replies arrive through a StreamDecoder:
//
//   LinkClient<M> client;  StreamDecoder rx;  std::uint8_t wire[kMaxWireFrame];
//   send(wire, client.sensor_frame(frame, wire));
//   for each received byte b:
//     if (rx.push(b) == StreamDecoder::Event::kFrame) {
//       const Reply r = client.accept(rx.frame());
//       if (r.ok() && r.type == MessageType::kStepResult) decode_step_result<M>(r.payload, result);
//     }
//
// Sequence numbers: every request carries next_sequence(); it advances when
// accept() sees the success reply to that number (one request in flight).
// After an error reply the next request reuses the number, which is what the
// device expects. Allocation-free, so a board could use it too.
#ifndef HADYNET_FIRMWARE_LINK_LINK_CLIENT_H_
#define HADYNET_FIRMWARE_LINK_LINK_CLIENT_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_contract.h"
#include "firmware/link/frame.h"
#include "firmware/link/messages.h"

namespace hadynet::link {

// One reply frame, checked at the frame level.
struct Reply {
  Status status;  // CRC, lengths, version; and the type (kUnknownType if not a reply type)
  MessageType type = MessageType::kError;
  std::uint16_t sequence = 0;
  std::span<const std::uint8_t> payload;  // points into the frame given to parse_reply
  constexpr bool ok() const noexcept { return status.ok() && type != MessageType::kError; }
};

constexpr bool is_reply_type(std::uint8_t type) noexcept {
  return type == static_cast<std::uint8_t>(MessageType::kError) ||
         ((type & kReplyBit) != 0 && is_request_type(static_cast<std::uint8_t>(type & ~kReplyBit)));
}

constexpr Reply parse_reply(std::span<const std::uint8_t> frame) noexcept {
  Reply r;
  Frame f;
  r.status = parse_frame(frame, f);
  if (!r.status.ok()) return r;
  if (!is_reply_type(f.type)) {
    r.status = {ErrorCode::kUnknownType, "not a reply type"};
    return r;
  }
  r.type = static_cast<MessageType>(f.type);
  r.sequence = f.sequence;
  r.payload = f.payload;
  return r;
}

template <firmware::GeneratedModel M>
class LinkClient {
 public:
  // Each request builder writes the request's wire bytes (COBS + 0x00) into
  // `wire` and returns their count: 0 only if `wire` is too small
  // (kMaxWireFrame always suffices).
  std::size_t info_request(std::span<std::uint8_t> wire) noexcept {
    return request(MessageType::kInfoRequest, 0, wire);
  }

  std::size_t sensor_frame(const firmware::SensorFrame<M>& frame, std::span<std::uint8_t> wire) noexcept {
    return request(MessageType::kSensorFrame, encode_sensor_frame<M>(frame, payload()), wire);
  }

  std::size_t set_pb_state(std::uint16_t state, std::span<std::uint8_t> wire) noexcept {
    SetPbRequest<M> q;
    q.kind = PbKind::kState;
    q.state = state;
    return request(MessageType::kSetPb, encode_set_pb<M>(q, payload()), wire);
  }

  // PB values in standardised units.
  std::size_t set_pb(const float (&values)[M::kPb], std::span<std::uint8_t> wire) noexcept {
    SetPbRequest<M> q;
    q.kind = PbKind::kValues;
    for (int i = 0; i < M::kPb; ++i) q.values[i] = values[i];
    return request(MessageType::kSetPb, encode_set_pb<M>(q, payload()), wire);
  }

  std::size_t set_mode(firmware::Mode mode, std::span<std::uint8_t> wire) noexcept {
    return request(MessageType::kSetMode, encode_set_mode(mode, payload()), wire);
  }

  std::size_t reset(std::span<std::uint8_t> wire) noexcept { return request(MessageType::kReset, 0, wire); }

  // The host's half of the autonomous loop's next frame (reply 0x86).
  std::size_t muscle_state(const app::MuscleState<M>& state, std::span<std::uint8_t> wire) noexcept {
    return request(MessageType::kMuscleState, encode_muscle_state<M>(state, payload()), wire);
  }

  // Loadcell offsets: zero them at the latest reading, or clear them (reply 0x87).
  std::size_t tare(TareAction action, std::span<std::uint8_t> wire) noexcept {
    return request(MessageType::kTare, encode_tare(action, payload()), wire);
  }

  // PB adaptation: on, off, adopt the adapted PB, or its status (reply 0x89).
  std::size_t adapt(const AdaptRequest& q, std::span<std::uint8_t> wire) noexcept {
    return request(MessageType::kAdapt, encode_adapt(q, payload()), wire);
  }

  // The autonomous loop's latest period record (reply 0x88).
  std::size_t period_result_request(std::span<std::uint8_t> wire) noexcept {
    return request(MessageType::kPeriodResultRequest, 0, wire);
  }

  // Any frame, valid or not, with the given header fields (tests, the fuzz
  // corpus tool); does not touch the sequence number.
  std::size_t raw_frame(std::uint8_t version, std::uint8_t type, std::uint16_t sequence,
                        std::span<const std::uint8_t> payload, std::span<std::uint8_t> wire) noexcept {
    FrameBuilder builder(frame_);
    const std::span<std::uint8_t> room = builder.payload();
    if (payload.size() > room.size()) return 0;
    for (std::size_t i = 0; i < payload.size(); ++i) room[i] = payload[i];
    return finish(builder.finish_raw(version, type, sequence, payload.size()), wire);
  }

  // Checks a decoded reply frame; a success reply to the current request
  // advances the sequence number.
  constexpr Reply accept(std::span<const std::uint8_t> frame) noexcept {
    const Reply r = parse_reply(frame);
    if (r.ok() && r.sequence == next_) next_ = static_cast<std::uint16_t>(next_ + 1u);
    return r;
  }

  constexpr std::uint16_t next_sequence() const noexcept { return next_; }
  constexpr void set_next_sequence(std::uint16_t sequence) noexcept { next_ = sequence; }

 private:
  // The payload is already in payload() (the request builders encode into it).
  std::size_t request(MessageType type, std::size_t payload_size, std::span<std::uint8_t> wire) noexcept {
    FrameBuilder builder(frame_);
    return finish(builder.finish(type, next_, payload_size), wire);
  }

  std::size_t finish(std::size_t frame_size, std::span<std::uint8_t> wire) noexcept {
    if (frame_size == 0) return 0;
    return encode_for_wire(std::span<const std::uint8_t>(frame_).first(frame_size), wire);
  }

  std::span<std::uint8_t> payload() noexcept { return FrameBuilder(frame_).payload(); }

  std::uint16_t next_ = 0;
  std::uint8_t frame_[kMaxFrame] = {};  // the request being built, decoded
};

}  // namespace hadynet::link

#endif  // HADYNET_FIRMWARE_LINK_LINK_CLIENT_H_
