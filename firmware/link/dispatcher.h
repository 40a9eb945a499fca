// The device side of the link protocol (docs/protocol.md): one received,
// decoded frame in, exactly one decoded reply frame out, executed on a
// firmware::HadynetRuntime. Pure code, no I/O: the transport (a board's UART,
// a pty, the tests) moves the bytes; DeviceLink (device_link.h) adds the
// COBS stream on both sides.
//
// Sequence numbers: the first request's number is accepted, after that each
// request must carry the previous executed request's number + 1 (mod 2^16).
// A reset request is accepted with any number and restarts the sequence. The
// expectation advances only when a request is executed.
//
// Robustness: a frame that is not executed gets an error reply (0x7F) and
// changes nothing — not the runtime (history, plan, PB, mode), not the
// autonomous loop (muscle state, tare offsets, records), not the sequence
// expectation.
//
// The autonomous 5 Hz loop (firmware/app/period_loop.h) belongs to the
// dispatcher: the link feeds it muscle states (0x06) and tare requests
// (0x07) and reads its latest record (0x08); the firmware's main loop runs
// its periods through loop(). A sensor frame (0x02) or a reset (0x05) makes
// the loop forget its muscle state, so the two ways of stepping the runtime
// never interleave.
#ifndef HADYNET_FIRMWARE_LINK_DISPATCHER_H_
#define HADYNET_FIRMWARE_LINK_DISPATCHER_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/app/channel_layout.h"
#include "firmware/app/period_loop.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_contract.h"
#include "firmware/link/frame.h"
#include "firmware/link/messages.h"

namespace hadynet::link {

template <firmware::GeneratedModel M>
class LinkDispatcher {
 public:
  using Runtime = firmware::HadynetRuntime<M>;

  explicit LinkDispatcher(Runtime& runtime) noexcept : runtime_(runtime), loop_(runtime) {}

  // Handles one decoded frame; writes the reply frame (decoded, not yet
  // COBS-encoded) into `reply` and returns its size (always > 0).
  std::size_t handle(std::span<const std::uint8_t> frame, std::span<std::uint8_t, kMaxFrame> reply) noexcept {
    Frame f;
    const Status parsed = parse_frame(frame, f);
    if (!parsed.ok()) return error_reply(parsed.code, f.sequence, parsed.reason, reply);
    if (!is_request_type(f.type))
      return error_reply(ErrorCode::kUnknownType, f.sequence, "unknown message type", reply);
    const auto type = static_cast<MessageType>(f.type);
    if (type != MessageType::kReset && synchronised_ && f.sequence != expected_) {
      char reason[kMaxReason + 1];
      out_of_order_reason(reason);
      return error_reply(ErrorCode::kOutOfOrder, f.sequence, reason, reply);
    }

    const auto refuse = [&](const Status& s) { return error_reply(s.code, f.sequence, s.reason, reply); };
    FrameBuilder builder(reply);
    const std::span<std::uint8_t> payload = builder.payload();
    std::size_t payload_size = 0;
    switch (type) {
      case MessageType::kInfoRequest: {
        if (const Status s = decode_empty(f.payload); !s.ok()) return refuse(s);
        payload_size = encode_info(info_of<M>(runtime_.tensors()), payload);
        break;
      }
      case MessageType::kSensorFrame: {
        firmware::SensorFrame<M> in;
        if (const Status s = decode_sensor_frame<M>(f.payload, in); !s.ok()) return refuse(s);
        loop_.forget_muscle_state();
        const firmware::StepResult<M> out = runtime_.step(in);
        payload_size = encode_step_result<M>(out, payload);
        break;
      }
      case MessageType::kSetPb: {
        SetPbRequest<M> q;
        if (const Status s = decode_set_pb<M>(f.payload, q); !s.ok()) return refuse(s);
        if (q.kind == PbKind::kState) {
          // decode_set_pb checked the range, so the runtime accepts it.
          if (!runtime_.set_pb_state(q.state))
            return refuse({ErrorCode::kBadValue, "set PB state: state out of range"});
        } else {
          runtime_.set_pb(q.values);
        }
        break;
      }
      case MessageType::kSetMode: {
        firmware::Mode mode{};
        if (const Status s = decode_set_mode(f.payload, mode); !s.ok()) return refuse(s);
        runtime_.set_mode(mode);
        break;
      }
      case MessageType::kReset: {
        if (const Status s = decode_empty(f.payload); !s.ok()) return refuse(s);
        runtime_.reset();
        loop_.forget_muscle_state();
        break;
      }
      case MessageType::kMuscleState: {
        app::MuscleState<M> in;
        if (const Status s = decode_muscle_state<M>(f.payload, in); !s.ok()) return refuse(s);
        payload_size = encode_muscle_state_ack(loop_.receive_muscle_state(in), payload);
        break;
      }
      case MessageType::kTare: {
        TareAction action{};
        if (const Status s = decode_tare(f.payload, action); !s.ok()) return refuse(s);
        if (action == TareAction::kZero) {
          if (!loop_.tare()) return refuse({ErrorCode::kNotReady, "tare: no loadcell reading yet"});
        } else {
          loop_.clear_tare();
        }
        payload_size = encode_tare_ack<M>(loop_.tare_offsets_N(), payload);
        break;
      }
      case MessageType::kPeriodResultRequest: {
        if (const Status s = decode_empty(f.payload); !s.ok()) return refuse(s);
        payload_size = encode_period_result<M>(loop_.latest(), payload);
        break;
      }
      case MessageType::kAdapt: {
        AdaptRequest q;
        if (const Status s = decode_adapt(f.payload, q); !s.ok()) return refuse(s);
        typename firmware::PbAdapter<M>::Settings settings = runtime_.adapter().settings();
        if (q.window_stride != 0) settings.window_stride = q.window_stride;
        if (q.windows_per_period != 0) settings.windows_per_period = q.windows_per_period;
        if (!firmware::PbAdapter<M>::valid(settings))
          return refuse({ErrorCode::kBadValue, "adapt: stride or windows per period out of range"});
        runtime_.set_adapt_settings(settings);
        if (q.action == AdaptAction::kOn) runtime_.set_adapting(true);
        if (q.action == AdaptAction::kOff) runtime_.set_adapting(false);
        if (q.action == AdaptAction::kAdopt) runtime_.use_adapted_pb();
        payload_size = encode_adapt_status<M>(adapt_status_of(runtime_), payload);
        break;
      }
      default:  // is_request_type() admits no other type
        return error_reply(ErrorCode::kUnknownType, f.sequence, "unknown message type", reply);
    }
    synchronised_ = true;
    expected_ = static_cast<std::uint16_t>(f.sequence + 1u);
    return builder.finish(reply_type_of(type), f.sequence, payload_size);
  }

  // The error reply for a frame the stream decoder rejected before a frame
  // existed (kOversize, or kTruncated for a cut COBS block): sequence 0.
  std::size_t stream_error(ErrorCode code, const char* reason, std::span<std::uint8_t, kMaxFrame> reply) noexcept {
    return error_reply(code, 0, reason, reply);
  }

  // Sequence state: false until the first request is executed (then any
  // number is accepted); afterwards the number the next request must carry.
  bool synchronised() const noexcept { return synchronised_; }
  std::uint16_t expected_sequence() const noexcept { return expected_; }

  const Runtime& runtime() const noexcept { return runtime_; }

  // The autonomous loop: the main loop runs its periods (run_period,
  // end_period) and takes its records here.
  app::PeriodLoop<M>& loop() noexcept { return loop_; }
  const app::PeriodLoop<M>& loop() const noexcept { return loop_; }

 private:
  static std::size_t error_reply(ErrorCode code, std::uint16_t sequence, const char* reason,
                                 std::span<std::uint8_t, kMaxFrame> reply) noexcept {
    FrameBuilder builder(reply);
    const std::size_t n = encode_error(code, sequence, reason, builder.payload());
    return builder.finish(MessageType::kError, sequence, n);
  }

  // "out of order: expected NNNNN" (NUL-terminated).
  void out_of_order_reason(char (&out)[kMaxReason + 1]) const noexcept {
    constexpr char kPrefix[] = "out of order: expected ";
    std::size_t n = 0;
    for (const char c : kPrefix) {
      if (c == '\0') break;
      out[n++] = c;
    }
    char digits[5];
    std::size_t k = 0;
    std::uint16_t v = expected_;
    do {
      digits[k++] = static_cast<char>('0' + v % 10);
      v = static_cast<std::uint16_t>(v / 10);
    } while (v != 0);
    while (k > 0) out[n++] = digits[--k];
    out[n] = '\0';
  }

  Runtime& runtime_;
  app::PeriodLoop<M> loop_;
  bool synchronised_ = false;
  std::uint16_t expected_ = 0;
};

}  // namespace hadynet::link

#endif  // HADYNET_FIRMWARE_LINK_DISPATCHER_H_
