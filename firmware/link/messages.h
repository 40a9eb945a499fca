// Payloads of the link's messages (docs/protocol.md, "Messages"): encode and
// decode for each, sized from the generated model M at compile time. Pure,
// bounded, allocation-free; firmware and host tools share them.
//
// Encoders write into a caller buffer (usually FrameBuilder::payload()) and
// return the payload size, 0 if the buffer is too small (every payload but
// the empty acks is at least one byte). Decoders of requests return a Status
// whose code is the error reply's (kBadPayloadLength, kBadValue); decoders of
// replies return false for a malformed payload.
#ifndef HADYNET_FIRMWARE_LINK_MESSAGES_H_
#define HADYNET_FIRMWARE_LINK_MESSAGES_H_

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/app/channel_layout.h"
#include "firmware/app/period_record.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_contract.h"
#include "firmware/link/frame.h"

namespace hadynet::link {

inline constexpr std::size_t kMaxGeneratorVersion = 32;  // bytes of the info reply's generator string
inline constexpr std::size_t kMaxReason = 64;            // bytes of an error reply's reason text

// Payload sizes (bytes) that do not depend on the model.
inline constexpr std::size_t kInfoPayloadMax = 8 + 2 + 1 + 1 + 8 * 2 + 1 + 4 + 1 + kMaxGeneratorVersion;
inline constexpr std::size_t kSetModePayload = 1;
inline constexpr std::size_t kSetPbStatePayload = 1 + 2;
inline constexpr std::size_t kErrorPayloadMax = 1 + 2 + 1 + kMaxReason;
inline constexpr std::size_t kTarePayload = 1;
inline constexpr std::size_t kMuscleStateAckPayload = 4;
inline constexpr std::size_t kAdaptPayload = 3;

// Payload sizes (bytes) for model M; the build fails if M is too large for
// version-1 frames.
template <firmware::GeneratedModel M>
struct PayloadSizes {
  static constexpr std::size_t kSensorFrame = 4 * (M::kY + M::kU);
  static constexpr std::size_t kStepResult = 1 + 4 * M::kY + 4 + 4 * M::kU;
  static constexpr std::size_t kSetPbValues = 1 + 4 * M::kPb;
  static constexpr std::size_t kAdaptStatus = 1 + 4 + 4 + 2 + 1 + 1 + 4 + 2 + 4 + 2 + 4 + 4 * M::kPb;
  // The autonomous loop's messages (channel_layout.h: kMuscleY observed
  // channels that are not loadcells, kLoadcells loadcells).
  static constexpr std::size_t kMuscleState = 4 * (app::ChannelLayout<M>::kMuscleY + M::kU);
  static constexpr std::size_t kTareAck = 4 * app::ChannelLayout<M>::kLoadcells;
  static constexpr std::size_t kPeriodResult =
      4 + 4 + 1 + 2 + 4 + 4 + 4 + 4 * (app::ChannelLayout<M>::kLoadcells + 1 + M::kY + M::kU) + 4 + 2 + 4 + 2 + 4;
  static_assert(kSensorFrame <= kMaxPayload && kStepResult <= kMaxPayload && kSetPbValues <= kMaxPayload &&
                    kAdaptStatus <= kMaxPayload,
                "the model's messages exceed the protocol's kMaxPayload");
  static_assert(kMuscleState <= kMaxPayload && kTareAck <= kMaxPayload && kPeriodResult <= kMaxPayload,
                "the model's messages exceed the protocol's kMaxPayload");
};
static_assert(kInfoPayloadMax <= kMaxPayload && kErrorPayloadMax <= kMaxPayload);

// IEEE binary32: finite unless the exponent bits are all ones (inf, NaN).
constexpr bool is_finite_f32(float v) noexcept {
  return (std::bit_cast<std::uint32_t>(v) & 0x7F800000u) != 0x7F800000u;
}

// ---- 0x81 info

// firmware::Numeric on the wire (one byte; the values are the protocol's).
enum class WireNumeric : std::uint8_t { kQ15 = 0, kF32 = 1 };
constexpr WireNumeric to_wire(firmware::Numeric n) noexcept {
  return n == firmware::Numeric::kQ15 ? WireNumeric::kQ15 : WireNumeric::kF32;
}
// "q15", "f32", or "?" for a byte that names neither.
constexpr const char* numeric_name(std::uint8_t wire) noexcept {
  return wire == static_cast<std::uint8_t>(WireNumeric::kQ15)   ? firmware::numeric_name(firmware::Numeric::kQ15)
         : wire == static_cast<std::uint8_t>(WireNumeric::kF32) ? firmware::numeric_name(firmware::Numeric::kF32)
                                                                 : "?";
}

struct InfoReply {
  std::uint64_t model_hash = 0;  // FNV-1a 64 of the model file
  std::uint16_t contract_version = 0;
  std::uint8_t protocol_version = 0;
  std::uint8_t numeric = 0;  // WireNumeric
  std::uint16_t x = 0, u = 0, y = 0, pb = 0, hidden = 0, states = 0;
  std::uint16_t detect_steps = 0;     // N_detect
  std::uint16_t control_horizon = 0;  // N_control
  std::uint8_t has_detection = 0;
  float detect_threshold = 0.0f;  // C_detect on d
  std::uint8_t generator_version_size = 0;
  char generator_version[kMaxGeneratorVersion + 1] = {};  // NUL-terminated
};

// The info of a firmware of shape M running `tensors` (the compiled-in
// model by default; model hash and threshold are the running model's), the
// generator string cut at kMaxGeneratorVersion bytes.
template <firmware::GeneratedModel M>
constexpr InfoReply info_of(const firmware::ModelTensors<M>& tensors = firmware::kCompiledTensors<M>) noexcept {
  InfoReply r;
  r.model_hash = tensors.model_hash;
  r.contract_version = static_cast<std::uint16_t>(M::kContractVersion);
  r.protocol_version = kProtocolVersion;
  r.numeric = static_cast<std::uint8_t>(to_wire(M::kNumeric));
  r.x = static_cast<std::uint16_t>(M::kX);
  r.u = static_cast<std::uint16_t>(M::kU);
  r.y = static_cast<std::uint16_t>(M::kY);
  r.pb = static_cast<std::uint16_t>(M::kPb);
  r.hidden = static_cast<std::uint16_t>(M::kHidden);
  r.states = static_cast<std::uint16_t>(M::kStates);
  r.detect_steps = static_cast<std::uint16_t>(M::kDetectSteps);
  r.control_horizon = static_cast<std::uint16_t>(M::kControlHorizon);
  r.has_detection = M::kHasDetection ? 1 : 0;
  r.detect_threshold = tensors.detect_threshold;
  const char* g = M::kGeneratorVersion;
  std::size_t n = 0;
  while (n < kMaxGeneratorVersion && g[n] != '\0') {
    r.generator_version[n] = g[n];
    ++n;
  }
  r.generator_version[n] = '\0';
  r.generator_version_size = static_cast<std::uint8_t>(n);
  return r;
}

constexpr std::size_t encode_info(const InfoReply& r, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  w.u64(r.model_hash);
  w.u16(r.contract_version);
  w.u8(r.protocol_version);
  w.u8(r.numeric);
  for (const std::uint16_t d : {r.x, r.u, r.y, r.pb, r.hidden, r.states, r.detect_steps, r.control_horizon}) w.u16(d);
  w.u8(r.has_detection);
  w.f32(r.detect_threshold);
  const std::uint8_t n = r.generator_version_size <= kMaxGeneratorVersion
                             ? r.generator_version_size
                             : static_cast<std::uint8_t>(kMaxGeneratorVersion);
  w.u8(n);
  for (std::size_t i = 0; i < n; ++i) w.u8(static_cast<std::uint8_t>(r.generator_version[i]));
  return w.ok() ? w.size() : 0;
}

constexpr bool decode_info(std::span<const std::uint8_t> in, InfoReply& r) noexcept {
  ByteReader rd(in);
  r = InfoReply{};
  r.model_hash = rd.u64();
  r.contract_version = rd.u16();
  r.protocol_version = rd.u8();
  r.numeric = rd.u8();
  for (std::uint16_t* d : {&r.x, &r.u, &r.y, &r.pb, &r.hidden, &r.states, &r.detect_steps, &r.control_horizon}) {
    *d = rd.u16();
  }
  r.has_detection = rd.u8();
  r.detect_threshold = rd.f32();
  const std::uint8_t n = rd.u8();
  if (!rd.ok() || n > kMaxGeneratorVersion || rd.remaining() != n) return false;
  for (std::size_t i = 0; i < n; ++i) r.generator_version[i] = static_cast<char>(rd.u8());
  r.generator_version[n] = '\0';
  r.generator_version_size = n;
  return rd.ok();
}

// ---- 0x02 sensor frame: y[kY], u_prev[kU] (f32, physical units)

template <firmware::GeneratedModel M>
constexpr std::size_t encode_sensor_frame(const firmware::SensorFrame<M>& f, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  for (const float v : f.y) w.f32(v);
  for (const float v : f.u_prev) w.f32(v);
  return w.ok() ? w.size() : 0;
}

// Non-finite sensor values are passed on: the runtime maps NaN to the
// channel mean and saturates infinities (docs/firmware.md).
template <firmware::GeneratedModel M>
constexpr Status decode_sensor_frame(std::span<const std::uint8_t> in, firmware::SensorFrame<M>& f) noexcept {
  if (in.size() != PayloadSizes<M>::kSensorFrame) return {ErrorCode::kBadPayloadLength, "sensor frame: wrong size"};
  ByteReader rd(in);
  for (float& v : f.y) v = rd.f32();
  for (float& v : f.u_prev) v = rd.f32();
  return {};
}

// ---- 0x82 step result: flags u8, prediction[kY], d, command[kU] (f32)

inline constexpr std::uint8_t kFlagPredictionValid = 1u << 0;
inline constexpr std::uint8_t kFlagDistanceValid = 1u << 1;
inline constexpr std::uint8_t kFlagContact = 1u << 2;
inline constexpr std::uint8_t kFlagCommandValid = 1u << 3;

template <firmware::GeneratedModel M>
constexpr std::size_t encode_step_result(const firmware::StepResult<M>& r, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  std::uint8_t flags = 0;
  if (r.prediction_valid) flags |= kFlagPredictionValid;
  if (r.distance_valid) flags |= kFlagDistanceValid;
  if (r.contact) flags |= kFlagContact;
  if (r.command_valid) flags |= kFlagCommandValid;
  w.u8(flags);
  for (const float v : r.prediction) w.f32(v);
  w.f32(r.d);
  for (const float v : r.command) w.f32(v);
  return w.ok() ? w.size() : 0;
}

template <firmware::GeneratedModel M>
constexpr bool decode_step_result(std::span<const std::uint8_t> in, firmware::StepResult<M>& r) noexcept {
  if (in.size() != PayloadSizes<M>::kStepResult) return false;
  ByteReader rd(in);
  const std::uint8_t flags = rd.u8();
  r.prediction_valid = (flags & kFlagPredictionValid) != 0;
  r.distance_valid = (flags & kFlagDistanceValid) != 0;
  r.contact = (flags & kFlagContact) != 0;
  r.command_valid = (flags & kFlagCommandValid) != 0;
  for (float& v : r.prediction) v = rd.f32();
  r.d = rd.f32();
  for (float& v : r.command) v = rd.f32();
  return rd.ok() && (flags & 0xF0u) == 0;
}

// ---- 0x03 set PB: kind u8; kind 0: state index u16; kind 1: kPb f32
// (standardised PB values, all finite).

enum class PbKind : std::uint8_t { kState = 0, kValues = 1 };

template <firmware::GeneratedModel M>
struct SetPbRequest {
  PbKind kind = PbKind::kState;
  std::uint16_t state = 0;    // kind kState: row of the PB table
  float values[M::kPb] = {};  // kind kValues
};

template <firmware::GeneratedModel M>
constexpr std::size_t encode_set_pb(const SetPbRequest<M>& q, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(q.kind));
  if (q.kind == PbKind::kState) {
    w.u16(q.state);
  } else {
    for (const float v : q.values) w.f32(v);
  }
  return w.ok() ? w.size() : 0;
}

// Checks size, kind, state range (< M::kStates) and finiteness.
template <firmware::GeneratedModel M>
constexpr Status decode_set_pb(std::span<const std::uint8_t> in, SetPbRequest<M>& q) noexcept {
  if (in.empty()) return {ErrorCode::kBadPayloadLength, "set PB: empty payload"};
  ByteReader rd(in);
  const std::uint8_t kind = rd.u8();
  if (kind == static_cast<std::uint8_t>(PbKind::kState)) {
    if (in.size() != kSetPbStatePayload) return {ErrorCode::kBadPayloadLength, "set PB state: wrong size"};
    q.kind = PbKind::kState;
    q.state = rd.u16();
    if (q.state >= M::kStates) return {ErrorCode::kBadValue, "set PB state: state out of range"};
    return {};
  }
  if (kind == static_cast<std::uint8_t>(PbKind::kValues)) {
    if (in.size() != PayloadSizes<M>::kSetPbValues) return {ErrorCode::kBadPayloadLength, "set PB values: wrong size"};
    q.kind = PbKind::kValues;
    for (float& v : q.values) {
      v = rd.f32();
      if (!is_finite_f32(v)) return {ErrorCode::kBadValue, "set PB values: non-finite value"};
    }
    return {};
  }
  return {ErrorCode::kBadValue, "set PB: unknown kind"};
}

// ---- 0x04 set mode: u8 (0 observe, 1 detect, 2 control)

constexpr std::size_t encode_set_mode(firmware::Mode mode, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(mode));
  return w.ok() ? w.size() : 0;
}

constexpr Status decode_set_mode(std::span<const std::uint8_t> in, firmware::Mode& mode) noexcept {
  if (in.size() != kSetModePayload) return {ErrorCode::kBadPayloadLength, "set mode: wrong size"};
  if (in[0] > static_cast<std::uint8_t>(firmware::Mode::kControl))
    return {ErrorCode::kBadValue, "set mode: unknown mode"};
  mode = static_cast<firmware::Mode>(in[0]);
  return {};
}

// ---- 0x01 info request, 0x05 reset, and the acks: empty payloads

constexpr Status decode_empty(std::span<const std::uint8_t> in) noexcept {
  if (!in.empty()) return {ErrorCode::kBadPayloadLength, "payload must be empty"};
  return {};
}

// ---- 0x06 muscle state: y_muscle[kMuscleY], u_prev[kU] (f32, physical
// units; app::ChannelLayout: the observed channels that are not loadcells,
// in y order). Non-finite values are passed on, as in a sensor frame.

template <firmware::GeneratedModel M>
constexpr std::size_t encode_muscle_state(const app::MuscleState<M>& m, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  for (const float v : m.y) w.f32(v);
  for (const float v : m.u_prev) w.f32(v);
  return w.ok() ? w.size() : 0;
}

template <firmware::GeneratedModel M>
constexpr Status decode_muscle_state(std::span<const std::uint8_t> in, app::MuscleState<M>& m) noexcept {
  if (in.size() != PayloadSizes<M>::kMuscleState) return {ErrorCode::kBadPayloadLength, "muscle state: wrong size"};
  ByteReader rd(in);
  for (float& v : m.y) v = rd.f32();
  for (float& v : m.u_prev) v = rd.f32();
  return {};
}

// 0x86 muscle state ack: u32, the sequence number of the period record that
// will use this muscle state fresh (the next one).
constexpr std::size_t encode_muscle_state_ack(std::uint32_t first_record, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  w.u32(first_record);
  return w.ok() ? w.size() : 0;
}

constexpr bool decode_muscle_state_ack(std::span<const std::uint8_t> in, std::uint32_t& first_record) noexcept {
  if (in.size() != kMuscleStateAckPayload) return false;
  ByteReader rd(in);
  first_record = rd.u32();
  return rd.ok();
}

// ---- 0x07 tare: action u8 (0: offsets := the latest loadcell reading,
// 1: offsets := 0). 0x87 ack: the offsets now in use, f32[kLoadcells], N.

enum class TareAction : std::uint8_t { kZero = 0, kClear = 1 };

constexpr std::size_t encode_tare(TareAction action, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(action));
  return w.ok() ? w.size() : 0;
}

constexpr Status decode_tare(std::span<const std::uint8_t> in, TareAction& action) noexcept {
  if (in.size() != kTarePayload) return {ErrorCode::kBadPayloadLength, "tare: wrong size"};
  if (in[0] > static_cast<std::uint8_t>(TareAction::kClear)) return {ErrorCode::kBadValue, "tare: unknown action"};
  action = static_cast<TareAction>(in[0]);
  return {};
}

// (Loadcell arrays hold app::ChannelLayout<M>::kLoadcellSlots entries; the
// first kLoadcells are on the wire.)
template <firmware::GeneratedModel M>
constexpr std::size_t encode_tare_ack(const float (&offsets_N)[app::ChannelLayout<M>::kLoadcellSlots],
                                      std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  for (int k = 0; k < app::ChannelLayout<M>::kLoadcells; ++k) w.f32(offsets_N[k]);
  return w.size() == PayloadSizes<M>::kTareAck && w.ok() ? w.size() : 0;
}

template <firmware::GeneratedModel M>
constexpr bool decode_tare_ack(std::span<const std::uint8_t> in,
                               float (&offsets_N)[app::ChannelLayout<M>::kLoadcellSlots]) noexcept {
  if (in.size() != PayloadSizes<M>::kTareAck) return false;
  ByteReader rd(in);
  for (float& v : offsets_N) v = 0.0f;
  for (int k = 0; k < app::ChannelLayout<M>::kLoadcells; ++k) offsets_N[k] = rd.f32();
  return rd.ok();
}

// ---- 0x08 period result request: empty. 0x88 period result: the loop's
// latest app::PeriodRecord, fields in its order: sequence u32, period u32,
// mode u8, flags u16, muscle_state_age u32, overruns u32, missed_periods u32,
// loadcells_N[kLoadcells] f32, d f32, prediction[kY] f32, command[kU] f32,
// adapt_updates u32, recognized_state u16, recognized_distance f32,
// other_object_state u16, other_object_distance f32.

template <firmware::GeneratedModel M>
constexpr std::size_t encode_period_result(const app::PeriodRecord<M>& r, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  w.u32(r.sequence);
  w.u32(r.period);
  w.u8(static_cast<std::uint8_t>(r.mode));
  w.u16(r.flags);
  w.u32(r.muscle_state_age);
  w.u32(r.overruns);
  w.u32(r.missed_periods);
  for (int k = 0; k < app::ChannelLayout<M>::kLoadcells; ++k) w.f32(r.loadcells_N[k]);
  w.f32(r.d);
  for (const float v : r.prediction) w.f32(v);
  for (const float v : r.command) w.f32(v);
  w.u32(r.adapt_updates);
  w.u16(r.recognized_state);
  w.f32(r.recognized_distance);
  w.u16(r.other_object_state);
  w.f32(r.other_object_distance);
  return w.ok() ? w.size() : 0;
}

// False for a wrong size, an unknown mode, unknown flag bits or a
// recognition naming a state the model's PB table does not have.
template <firmware::GeneratedModel M>
constexpr bool decode_period_result(std::span<const std::uint8_t> in, app::PeriodRecord<M>& r) noexcept {
  if (in.size() != PayloadSizes<M>::kPeriodResult) return false;
  ByteReader rd(in);
  r.sequence = rd.u32();
  r.period = rd.u32();
  const std::uint8_t mode = rd.u8();
  r.mode = static_cast<firmware::Mode>(mode);
  r.flags = rd.u16();
  r.muscle_state_age = rd.u32();
  r.overruns = rd.u32();
  r.missed_periods = rd.u32();
  for (float& v : r.loadcells_N) v = 0.0f;
  for (int k = 0; k < app::ChannelLayout<M>::kLoadcells; ++k) r.loadcells_N[k] = rd.f32();
  r.d = rd.f32();
  for (float& v : r.prediction) v = rd.f32();
  for (float& v : r.command) v = rd.f32();
  r.adapt_updates = rd.u32();
  r.recognized_state = rd.u16();
  r.recognized_distance = rd.f32();
  r.other_object_state = rd.u16();
  r.other_object_distance = rd.f32();
  const bool recognition_ok =
      !r.has(app::kRecordRecognition) ||
      (r.recognized_state < M::kStates &&
       (r.other_object_state < M::kStates || r.other_object_state == app::kRecordNoOtherObject));
  return rd.ok() && mode <= static_cast<std::uint8_t>(firmware::Mode::kControl) &&
         (r.flags & ~app::kRecordKnownFlags) == 0 && recognition_ok;
}

// ---- 0x09 adapt: action u8, window stride u8, windows per period u8
// (0: keep). 0x89 adapt status: below.

enum class AdaptAction : std::uint8_t {
  kStatus = 0,  // change nothing (but the settings given)
  kOn = 1,      // adaptation on, from the active PB (no change if already on)
  kOff = 2,     // adaptation off; the adapted PB is kept
  kAdopt = 3,   // the adapted PB becomes the active PB (detection, control)
};

struct AdaptRequest {
  AdaptAction action = AdaptAction::kStatus;
  std::uint8_t window_stride = 0;       // 0: keep
  std::uint8_t windows_per_period = 0;  // 0: keep
};

constexpr std::size_t encode_adapt(const AdaptRequest& q, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(q.action));
  w.u8(q.window_stride);
  w.u8(q.windows_per_period);
  return w.ok() ? w.size() : 0;
}

// Checks size and action; the settings' ranges are the adapter's (the
// dispatcher refuses what PbAdapter::valid refuses).
constexpr Status decode_adapt(std::span<const std::uint8_t> in, AdaptRequest& q) noexcept {
  if (in.size() != kAdaptPayload) return {ErrorCode::kBadPayloadLength, "adapt: wrong size"};
  if (in[0] > static_cast<std::uint8_t>(AdaptAction::kAdopt)) return {ErrorCode::kBadValue, "adapt: unknown action"};
  q.action = static_cast<AdaptAction>(in[0]);
  q.window_stride = in[1];
  q.windows_per_period = in[2];
  return {};
}

inline constexpr std::uint16_t kNoState = 0xFFFF;

// The adaptation's state as the 0x89 reply carries it: on u8, updates u32
// (steps taken), rejected u32 (steps the safeguard undid), windows u16
// (held), stride u8, windows per period u8, loss f32 (mean squared error of
// the last epoch, standardised), state u16 (nearest PB-table row of the
// adapted PB; 0xFFFF before the first step or without a table), distance
// f32, other u16 (nearest row of another object; 0xFFFF none), other
// distance f32, pb[kPb] f32 (the adapted PB, standardised).
template <firmware::GeneratedModel M>
struct AdaptStatus {
  std::uint8_t on = 0;
  std::uint32_t updates = 0;
  std::uint32_t rejected = 0;
  std::uint16_t windows = 0;
  std::uint8_t window_stride = 0;
  std::uint8_t windows_per_period = 0;
  float loss = 0.0f;
  std::uint16_t state = kNoState;
  float distance = 0.0f;
  std::uint16_t other_state = kNoState;
  float other_distance = 0.0f;
  float pb[M::kPb] = {};
};

template <firmware::GeneratedModel M>
AdaptStatus<M> adapt_status_of(const firmware::HadynetRuntime<M>& runtime) noexcept {
  const firmware::PbAdapter<M>& a = runtime.adapter();
  AdaptStatus<M> s;
  s.on = runtime.adapting() ? 1 : 0;
  s.updates = a.updates();
  s.rejected = a.rejected();
  s.windows = static_cast<std::uint16_t>(a.windows_held());
  s.window_stride = static_cast<std::uint8_t>(a.settings().window_stride);
  s.windows_per_period = static_cast<std::uint8_t>(a.settings().windows_per_period);
  s.loss = a.last_loss();
  if (a.updates() > 0) {
    const firmware::PbRecognition r = a.recognize();
    if (r.valid) {
      s.state = static_cast<std::uint16_t>(r.state);
      s.distance = r.distance;
      if (r.other_state >= 0) {
        s.other_state = static_cast<std::uint16_t>(r.other_state);
        s.other_distance = r.other_distance;
      }
    }
  }
  for (int i = 0; i < M::kPb; ++i) s.pb[i] = firmware::Numerics<M>::template to_real<M::kFracIn>(a.pb()[i]);
  return s;
}

template <firmware::GeneratedModel M>
constexpr std::size_t encode_adapt_status(const AdaptStatus<M>& s, std::span<std::uint8_t> out) noexcept {
  ByteWriter w(out);
  w.u8(s.on);
  w.u32(s.updates);
  w.u32(s.rejected);
  w.u16(s.windows);
  w.u8(s.window_stride);
  w.u8(s.windows_per_period);
  w.f32(s.loss);
  w.u16(s.state);
  w.f32(s.distance);
  w.u16(s.other_state);
  w.f32(s.other_distance);
  for (const float v : s.pb) w.f32(v);
  return w.ok() ? w.size() : 0;
}

template <firmware::GeneratedModel M>
constexpr bool decode_adapt_status(std::span<const std::uint8_t> in, AdaptStatus<M>& s) noexcept {
  if (in.size() != PayloadSizes<M>::kAdaptStatus) return false;
  ByteReader rd(in);
  s.on = rd.u8();
  s.updates = rd.u32();
  s.rejected = rd.u32();
  s.windows = rd.u16();
  s.window_stride = rd.u8();
  s.windows_per_period = rd.u8();
  s.loss = rd.f32();
  s.state = rd.u16();
  s.distance = rd.f32();
  s.other_state = rd.u16();
  s.other_distance = rd.f32();
  for (float& v : s.pb) v = rd.f32();
  return rd.ok() && s.on <= 1;
}

// ---- 0x7F error: code u8, offending sequence number u16, reason (u8 length + ASCII)

struct ErrorReply {
  ErrorCode code = ErrorCode::kNone;
  std::uint16_t sequence = 0;  // the offending frame's, 0 if unknown
  std::uint8_t reason_size = 0;
  char reason[kMaxReason + 1] = {};  // NUL-terminated
};

// `reason` is NUL-terminated ASCII, cut at kMaxReason bytes.
constexpr std::size_t encode_error(ErrorCode code, std::uint16_t sequence, const char* reason,
                                   std::span<std::uint8_t> out) noexcept {
  std::size_t n = 0;
  while (n < kMaxReason && reason[n] != '\0') ++n;
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(code));
  w.u16(sequence);
  w.u8(static_cast<std::uint8_t>(n));
  for (std::size_t i = 0; i < n; ++i) w.u8(static_cast<std::uint8_t>(reason[i]));
  return w.ok() ? w.size() : 0;
}

constexpr bool decode_error(std::span<const std::uint8_t> in, ErrorReply& e) noexcept {
  ByteReader rd(in);
  e = ErrorReply{};
  e.code = static_cast<ErrorCode>(rd.u8());
  e.sequence = rd.u16();
  const std::uint8_t n = rd.u8();
  if (!rd.ok() || n > kMaxReason || rd.remaining() != n) return false;
  for (std::size_t i = 0; i < n; ++i) e.reason[i] = static_cast<char>(rd.u8());
  e.reason[n] = '\0';
  e.reason_size = n;
  return rd.ok();
}

}  // namespace hadynet::link

#endif  // HADYNET_FIRMWARE_LINK_MESSAGES_H_
