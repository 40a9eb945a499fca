// The device end of the link with the build's generated models, driven over
// the wire (LinkClient -> COBS bytes -> DeviceLink -> reply bytes): info,
// step results, set PB, set mode, reset, sequence numbers. The link only
// moves bits (floats travel as their IEEE patterns), so every comparison with
// the runtime called directly is bit-exact, tolerance zero.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "link_test_device.h"

namespace hadynet::link {
namespace {

using namespace hadynet::link::testing;
using Q = model_q15::Model;
using F = model_f32::Model;
using firmware::Mode;

// A reply of the given type and sequence number (an error reply's code and
// reason are printed on mismatch).
void expect_reply(const Bytes& frame, MessageType type, std::uint16_t seq, Reply* out = nullptr) {
  const Reply r = parse_reply(frame);
  ASSERT_TRUE(r.status.ok()) << r.status.reason;
  if (r.type == MessageType::kError && type != MessageType::kError) {
    ErrorReply e;
    ASSERT_TRUE(decode_error(r.payload, e));
    FAIL() << "error reply " << static_cast<int>(e.code) << ": " << e.reason;
  }
  EXPECT_EQ(r.type, type);
  EXPECT_EQ(r.sequence, seq);
  if (out != nullptr) *out = r;
}

template <firmware::GeneratedModel M>
void check_info() {
  ZeroedDevice<M> dev;
  LinkClient<M> client;
  const Bytes reply = dev.send_one(wire_of([&](auto w) { return client.info_request(w); }));
  Reply r;
  expect_reply(reply, MessageType::kInfo, 0, &r);
  InfoReply info;
  ASSERT_TRUE(decode_info(r.payload, info));
  EXPECT_EQ(info.model_hash, M::kModelHash);
  EXPECT_EQ(info.contract_version, firmware::kModelContractVersion);
  EXPECT_EQ(info.protocol_version, 1);
  EXPECT_EQ(info.numeric, M::kNumeric == firmware::Numeric::kQ15 ? 0 : 1);
  EXPECT_EQ(info.x, M::kX);
  EXPECT_EQ(info.u, M::kU);
  EXPECT_EQ(info.y, M::kY);
  EXPECT_EQ(info.pb, M::kPb);
  EXPECT_EQ(info.hidden, M::kHidden);
  EXPECT_EQ(info.states, M::kStates);
  EXPECT_EQ(info.detect_steps, M::kDetectSteps);
  EXPECT_EQ(info.control_horizon, M::kControlHorizon);
  EXPECT_EQ(info.has_detection, M::kHasDetection ? 1 : 0);
  EXPECT_EQ(info.detect_threshold, M::kDetectThreshold);
  EXPECT_EQ(std::string(info.generator_version), std::string(M::kGeneratorVersion).substr(0, kMaxGeneratorVersion));
}

TEST(LinkDispatcher, InfoReportsTheCompiledModel) {
  check_info<Q>();
  check_info<F>();
}

// The same frames through the link and into a runtime called directly: every
// step result bit-identical, through observe, detect and control mode.
template <firmware::GeneratedModel M>
void check_steps_match_runtime(int frames, int control_from) {
  ZeroedDevice<M> dev;
  auto direct = std::make_unique<firmware::HadynetRuntime<M>>();
  LinkClient<M> client;
  client.set_next_sequence(65530);  // crosses the wrap-around

  for (int t = 0; t < frames; ++t) {
    const Mode mode = t < 3 ? Mode::kObserve : t < control_from ? Mode::kDetect : Mode::kControl;
    if (t == 0 || t == 3 || t == control_from) {
      const std::uint16_t seq = client.next_sequence();
      const Bytes ack = dev.send_one(wire_of([&](auto w) { return client.set_mode(mode, w); }));
      expect_reply(ack, MessageType::kSetModeAck, seq);
      client.accept(ack);
      direct->set_mode(mode);
    }
    const firmware::SensorFrame<M> frame = synthetic_frame<M>(t);
    const std::uint16_t seq = client.next_sequence();
    const Bytes reply = dev.send_one(wire_of([&](auto w) { return client.sensor_frame(frame, w); }));
    Reply r;
    expect_reply(reply, MessageType::kStepResult, seq, &r);
    client.accept(reply);
    firmware::StepResult<M> via_link;
    ASSERT_TRUE(decode_step_result<M>(r.payload, via_link));
    const firmware::StepResult<M> expected = direct->step(frame);
    expect_bit_identical<M>(via_link, expected, t);
    if (t >= M::kDetectSteps + 1) {
      EXPECT_TRUE(via_link.prediction_valid) << t;
    }
    if (t >= control_from) {
      EXPECT_TRUE(via_link.command_valid) << t;
    }
  }
  EXPECT_EQ(client.next_sequence(), static_cast<std::uint16_t>(65530 + frames + 3));
}

TEST(LinkDispatcher, StepResultsAreBitIdenticalToTheRuntimeQ15) { check_steps_match_runtime<Q>(24, 12); }
TEST(LinkDispatcher, StepResultsAreBitIdenticalToTheRuntimeF32) { check_steps_match_runtime<F>(12, 9); }

// PB adaptation over the link (0x09): switched on with settings, its status
// after every frame bit-identical to a runtime adapting directly; adopt
// makes the adapted PB the active one; off stops it.
TEST(LinkDispatcher, AdaptStatusFollowsTheRuntime) {
  ZeroedDevice<Q> dev;
  auto direct = std::make_unique<firmware::HadynetRuntime<Q>>();
  LinkClient<Q> client;
  const auto adapt = [&](AdaptRequest q) {
    const std::uint16_t seq = client.next_sequence();
    const Bytes reply = dev.send_one(wire_of([&](auto w) { return client.adapt(q, w); }));
    Reply r;
    expect_reply(reply, MessageType::kAdaptStatus, seq, &r);
    client.accept(reply);
    AdaptStatus<Q> status;
    EXPECT_TRUE(decode_adapt_status<Q>(r.payload, status));
    std::uint8_t expected[PayloadSizes<Q>::kAdaptStatus];
    EXPECT_EQ(encode_adapt_status<Q>(adapt_status_of(*direct), expected), r.payload.size());
    EXPECT_EQ(std::memcmp(expected, r.payload.data(), r.payload.size()), 0) << "status differs from the runtime's";
    return status;
  };
  // Every 8th window, 2 per period: the first step comes a few periods after
  // the 100th window.
  typename firmware::PbAdapter<Q>::Settings settings = direct->adapter().settings();
  settings.window_stride = 8;
  settings.windows_per_period = 2;
  ASSERT_TRUE(direct->set_adapt_settings(settings));
  direct->set_adapting(true);
  AdaptStatus<Q> status = adapt({AdaptAction::kOn, 8, 2});
  EXPECT_EQ(status.on, 1);
  EXPECT_EQ(status.window_stride, 8);
  EXPECT_EQ(status.windows_per_period, 2);
  const int frames = 100 + Q::kTrainSteps + 2 + 24;
  for (int t = 0; t < frames; ++t) {
    const firmware::SensorFrame<Q> frame = synthetic_frame<Q>(t);
    const std::uint16_t seq = client.next_sequence();
    const Bytes reply = dev.send_one(wire_of([&](auto w) { return client.sensor_frame(frame, w); }));
    expect_reply(reply, MessageType::kStepResult, seq);
    client.accept(reply);
    direct->step(frame);
    status = adapt({});
  }
  EXPECT_GT(status.updates, 0u) << "no adaptation step in " << frames << " frames";
  EXPECT_NE(status.state, kNoState);
  adapt({AdaptAction::kAdopt, 0, 0});
  direct->use_adapted_pb();
  EXPECT_EQ(std::memcmp(dev->runtime.pb(), direct->adapter().pb(), sizeof(direct->adapter().pb())), 0);
  direct->set_adapting(false);
  EXPECT_EQ(adapt({AdaptAction::kOff, 0, 0}).on, 0);
}

TEST(LinkDispatcher, SetPbByStateAndByValues) {
  ZeroedDevice<Q> dev;
  LinkClient<Q> client;
  ASSERT_GT(Q::kStates, 1);
  const std::uint16_t state = static_cast<std::uint16_t>(Q::kStates - 1);
  Bytes ack = dev.send_one(wire_of([&](auto w) { return client.set_pb_state(state, w); }));
  Reply r;
  expect_reply(ack, MessageType::kSetPbAck, 0, &r);
  EXPECT_TRUE(r.payload.empty());
  client.accept(ack);
  EXPECT_EQ(std::memcmp(dev->runtime.pb(), Q::kPbTable[state], sizeof(Q::kPbTable[state])), 0);

  float values[Q::kPb];
  for (int i = 0; i < Q::kPb; ++i) values[i] = 0.3f * static_cast<float>(i) - 1.0f;
  values[0] = 1e30f;  // finite: saturated into the format by the runtime
  ack = dev.send_one(wire_of([&](auto w) { return client.set_pb(values, w); }));
  expect_reply(ack, MessageType::kSetPbAck, 1);
  firmware::HadynetRuntime<Q> expected;
  expected.set_pb(values);
  EXPECT_EQ(std::memcmp(dev->runtime.pb(), expected.pb(), sizeof(expected.pb())), 0);
}

TEST(LinkDispatcher, SetModeEachMode) {
  ZeroedDevice<Q> dev;
  LinkClient<Q> client;
  for (Mode m : {Mode::kControl, Mode::kObserve, Mode::kDetect}) {
    const std::uint16_t seq = client.next_sequence();
    const Bytes ack = dev.send_one(wire_of([&](auto w) { return client.set_mode(m, w); }));
    Reply r;
    expect_reply(ack, MessageType::kSetModeAck, seq, &r);
    EXPECT_TRUE(r.payload.empty());
    client.accept(ack);
    EXPECT_EQ(dev->runtime.mode(), m);
  }
}

// Reset clears history and plan but keeps mode and PB: afterwards the device
// behaves like a fresh runtime given the same mode and PB.
TEST(LinkDispatcher, ResetClearsHistoryKeepsModeAndPb) {
  ZeroedDevice<Q> dev;
  LinkClient<Q> client;
  const auto exchange = [&](auto build) {
    const Bytes reply = dev.send_one(wire_of(build));
    client.accept(reply);
    return reply;
  };
  exchange([&](auto w) { return client.set_mode(Mode::kControl, w); });
  exchange([&](auto w) { return client.set_pb_state(2, w); });
  for (int t = 0; t < 9; ++t) {
    exchange([&](auto w) { return client.sensor_frame(synthetic_frame<Q>(t), w); });
  }
  // Reset is accepted with any number and restarts the sequence there.
  client.set_next_sequence(4242);
  const Bytes ack = exchange([&](auto w) { return client.reset(w); });
  expect_reply(ack, MessageType::kResetAck, 4242);
  EXPECT_EQ(dev->link.dispatcher().expected_sequence(), 4243);
  EXPECT_EQ(dev->runtime.mode(), Mode::kControl);

  firmware::HadynetRuntime<Q> fresh;
  fresh.set_mode(Mode::kControl);
  fresh.set_pb_state(2);
  for (int t = 100; t < 110; ++t) {
    const firmware::SensorFrame<Q> frame = synthetic_frame<Q>(t);
    const Bytes reply = exchange([&](auto w) { return client.sensor_frame(frame, w); });
    Reply r;
    expect_reply(reply, MessageType::kStepResult, static_cast<std::uint16_t>(4243 + (t - 100)), &r);
    firmware::StepResult<Q> via_link;
    ASSERT_TRUE(decode_step_result<Q>(r.payload, via_link));
    expect_bit_identical<Q>(via_link, fresh.step(frame), t);
  }
}

TEST(LinkDispatcher, FirstRequestSetsTheSequenceWhichThenWraps) {
  ZeroedDevice<Q> dev;
  EXPECT_FALSE(dev->link.dispatcher().synchronised());
  LinkClient<Q> client;
  client.set_next_sequence(65535);
  Bytes reply = dev.send_one(wire_of([&](auto w) { return client.info_request(w); }));
  expect_reply(reply, MessageType::kInfo, 65535);
  client.accept(reply);
  EXPECT_TRUE(dev->link.dispatcher().synchronised());
  EXPECT_EQ(dev->link.dispatcher().expected_sequence(), 0);
  reply = dev.send_one(wire_of([&](auto w) { return client.info_request(w); }));
  expect_reply(reply, MessageType::kInfo, 0);
}

// The worked example of docs/protocol.md §6, whose bytes were computed
// outside this code (Python's zlib.crc32 and an independent COBS encoder).
TEST(LinkProtocolDoc, WorkedExamples) {
  ZeroedDevice<Q> dev;
  LinkClient<Q> client;
  const Bytes info = wire_of([&](auto w) { return client.info_request(w); });
  EXPECT_EQ(info, (Bytes{0x03, 0x01, 0x01, 0x01, 0x01, 0x01, 0x05, 0xb6, 0x5b, 0xfe, 0x47, 0x00}));
  client.set_next_sequence(7);
  const Bytes set_mode = wire_of([&](auto w) { return client.set_mode(Mode::kControl, w); });
  EXPECT_EQ(set_mode, (Bytes{0x04, 0x01, 0x04, 0x07, 0x02, 0x01, 0x06, 0x02, 0xd7, 0x41, 0x66, 0xfd, 0x00}));
  Bytes reply;
  for (std::uint8_t b : set_mode) {
    const auto out = dev->link.receive(b);
    reply.insert(reply.end(), out.begin(), out.end());
  }
  EXPECT_EQ(reply, (Bytes{0x04, 0x01, 0x84, 0x07, 0x01, 0x01, 0x05, 0xed, 0x5c, 0x2f, 0xa3, 0x00}));
}

}  // namespace
}  // namespace hadynet::link
