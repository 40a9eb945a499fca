// One host-side conversation with a device running the firmware: requests
// go out numbered (firmware/link/link_client.h), each waits for its reply;
// an error reply or a timeout becomes a LinkError with the device's reason.
// The same protocol code as the firmware (docs/protocol.md).
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>

#include "firmware/link/link_client.h"
#include "firmware/link/stream_decoder.h"
#include "tools/link/byte_stream.h"

namespace hadynet::tools {

template <firmware::GeneratedModel M>
class LinkSession {
 public:
  // timeout_ms: how long one exchange (request to its reply) may take (a control period on a slow
  // device is ~0.1 s; QEMU without KVM is slower).
  explicit LinkSession(ByteStream& stream, int timeout_ms = 5000) : stream_(stream), timeout_ms_(timeout_ms) {}

  // Reset is accepted with any sequence number and restarts the numbering:
  // call it first to synchronise with a device that has talked to others.
  void reset() { transact(client_.reset(wire_), link::MessageType::kResetAck); }

  // Opens the conversation with a device that may still be starting (a UART
  // that is not enabled yet drops what arrives, e.g. STM32 on QEMU): sends a
  // delimiter and a reset every `retry_ms` until the reset is acknowledged,
  // ignoring error replies to half-received frames. The whole exchange ends
  // after timeout_ms, however the device behaves (a device that keeps
  // sending bytes does not extend it).
  void connect(int timeout_ms = 10000, int retry_ms = 300) {
    const std::uint8_t delimiter = 0;
    const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
    ExchangeCounts seen;
    while (Clock::now() < deadline) {
      stream_.write(std::span<const std::uint8_t>(&delimiter, 1));
      const std::size_t n = client_.reset(wire_);
      const std::uint16_t sequence = client_.next_sequence();
      stream_.write(std::span<const std::uint8_t>(wire_, n));
      const Clock::time_point resend = std::min(deadline, Clock::now() + std::chrono::milliseconds(retry_ms));
      std::uint8_t buffer[256];
      std::size_t got;
      while ((got = stream_.read(buffer, remaining_ms(resend))) > 0) {
        seen.bytes += got;
        for (std::size_t i = 0; i < got; ++i) {
          if (rx_.push(buffer[i]) != link::StreamDecoder::Event::kFrame) continue;
          ++seen.frames;
          const link::Reply r = client_.accept(rx_.frame());
          if (r.ok() && r.type == link::MessageType::kResetAck && r.sequence == sequence) return;
        }
        if (Clock::now() >= resend) break;
      }
    }
    throw LinkError(stream_.name() + ": the device did not acknowledge a reset within " +
                    std::to_string(timeout_ms) + " ms (" + seen.describe() + ")");
  }
  link::InfoReply info() {
    const link::Reply r = transact(client_.info_request(wire_), link::MessageType::kInfo);
    link::InfoReply info;
    if (!link::decode_info(r.payload, info)) throw LinkError(stream_.name() + ": malformed info reply");
    return info;
  }
  void set_mode(firmware::Mode mode) { transact(client_.set_mode(mode, wire_), link::MessageType::kSetModeAck); }
  void set_pb_state(std::uint16_t state) {
    transact(client_.set_pb_state(state, wire_), link::MessageType::kSetPbAck);
  }
  void set_pb(const float (&values)[M::kPb]) { transact(client_.set_pb(values, wire_), link::MessageType::kSetPbAck); }
  link::AdaptStatus<M> adapt(const link::AdaptRequest& q) {
    const link::Reply r = transact(client_.adapt(q, wire_), link::MessageType::kAdaptStatus);
    link::AdaptStatus<M> status;
    if (!link::decode_adapt_status<M>(r.payload, status)) throw LinkError(stream_.name() + ": malformed adapt status");
    return status;
  }
  firmware::StepResult<M> step(const firmware::SensorFrame<M>& frame) {
    const link::Reply r = transact(client_.sensor_frame(frame, wire_), link::MessageType::kStepResult);
    firmware::StepResult<M> result;
    if (!link::decode_step_result<M>(r.payload, result))
      throw LinkError(stream_.name() + ": malformed step result");
    return result;
  }

 private:
  using Clock = std::chrono::steady_clock;

  // What the device sent during one exchange, for the time-out message.
  struct ExchangeCounts {
    std::size_t bytes = 0;   // received
    std::size_t frames = 0;  // complete frames among them
    std::size_t stale = 0;   // well-formed replies to another request or of another type
    std::string describe() const {
      if (bytes == 0) return "it sent nothing";
      return "it sent " + std::to_string(bytes) + " bytes, " + std::to_string(frames) + " complete frames, " +
             std::to_string(stale) + " of them replies to other requests";
    }
  };

  static int remaining_ms(Clock::time_point deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    return left > 0 ? static_cast<int>(left) : 0;
  }

  // Sends the request in wire_ and returns its reply (of type `expected`).
  // The whole exchange, not each read, is bounded by timeout_ms: a device
  // that sends noise, or answers with a wrong sequence number forever, ends
  // in a LinkError saying what it sent.
  link::Reply transact(std::size_t wire_size, link::MessageType expected) {
    if (wire_size == 0) throw LinkError(stream_.name() + ": request does not fit a frame");
    const std::uint16_t sequence = client_.next_sequence();
    stream_.write(std::span<const std::uint8_t>(wire_, wire_size));
    const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(timeout_ms_);
    ExchangeCounts seen;
    std::uint8_t buffer[256];
    while (true) {
      const int left_ms = remaining_ms(deadline);
      const std::size_t n = left_ms > 0 ? stream_.read(buffer, left_ms) : 0;
      if (n == 0) {
        throw LinkError(stream_.name() + ": no reply to request " + std::to_string(sequence) + " within " +
                        std::to_string(timeout_ms_) + " ms (" + seen.describe() + ")");
      }
      seen.bytes += n;
      for (std::size_t i = 0; i < n; ++i) {
        if (rx_.push(buffer[i]) != link::StreamDecoder::Event::kFrame) continue;
        ++seen.frames;
        const link::Reply r = client_.accept(rx_.frame());
        if (!r.status.ok()) throw LinkError(stream_.name() + ": malformed reply frame");
        if (r.type == link::MessageType::kError) {
          link::ErrorReply e;
          const bool decoded = link::decode_error(r.payload, e);
          throw LinkError(stream_.name() + ": the device refused request " + std::to_string(sequence) + ": " +
                          (decoded ? std::string(e.reason) + " (code " + std::to_string(static_cast<int>(e.code)) + ")"
                                   : std::string("malformed error reply")));
        }
        if (r.sequence != sequence || r.type != expected) {  // a stale reply
          ++seen.stale;
          continue;
        }
        return r;
      }
    }
  }

  ByteStream& stream_;
  int timeout_ms_;
  link::LinkClient<M> client_;
  link::StreamDecoder rx_;
  std::uint8_t wire_[link::kMaxWireFrame] = {};
};

}  // namespace hadynet::tools
