// The firmware's autonomous 5 Hz loop (firmware/app/period_loop.h) as pure
// code, and its messages on the link (docs/protocol.md 0x06..0x08): no board,
// the tests play the board (loadcell readings, "period elapsed", work times).
//
// Expectations are exact (tolerance zero) throughout: the loop only copies
// bits into a sensor frame (a tare subtracts one float, and the expected
// value is that same subtraction), so a period must give the StepResult of
// the same frame sent by a host, bit for bit, and the same runtime state
// byte for byte.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "firmware/app/channel_layout.h"
#include "firmware/app/period_loop.h"
#include "firmware/app/period_record.h"
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

template <firmware::GeneratedModel M>
using Reading = typename app::PeriodLoop<M>::LoadcellReading;

// Frame t split into what the host sends and what the board reads.
template <firmware::GeneratedModel M>
void split(const firmware::SensorFrame<M>& frame, app::MuscleState<M>& muscle, Reading<M>& reading) {
  reading.valid = true;
  app::split_frame<M>(frame, muscle, reading.newtons);
}

// The decoded reply of one request; fails the test on an error reply.
template <firmware::GeneratedModel M>
Reply exchange(ZeroedDevice<M>& dev, LinkClient<M>& client, const Bytes& wire, MessageType expected,
               Bytes& storage) {
  const std::uint16_t seq = client.next_sequence();
  storage = dev.send_one(wire);
  const Reply r = client.accept(storage);
  EXPECT_TRUE(r.status.ok()) << r.status.reason;
  if (r.type == MessageType::kError) {
    ErrorReply e;
    decode_error(r.payload, e);
    ADD_FAILURE() << "error reply " << static_cast<int>(e.code) << ": " << e.reason;
  }
  EXPECT_EQ(r.type, expected);
  EXPECT_EQ(r.sequence, seq);
  return r;
}

template <firmware::GeneratedModel M>
app::PeriodRecord<M> request_record(ZeroedDevice<M>& dev, LinkClient<M>& client) {
  Bytes storage;
  const Reply r = exchange(dev, client, wire_of([&](auto w) { return client.period_result_request(w); }),
                           MessageType::kPeriodResult, storage);
  app::PeriodRecord<M> record;
  EXPECT_TRUE(decode_period_result<M>(r.payload, record));
  return record;
}

// A record's step fields against a StepResult, bit for bit.
template <firmware::GeneratedModel M>
void expect_record_is_step(const app::PeriodRecord<M>& r, const firmware::StepResult<M>& s, int t) {
  EXPECT_TRUE(r.has(app::kRecordStepped)) << t;
  EXPECT_EQ(r.has(app::kRecordPredictionValid), s.prediction_valid) << t;
  EXPECT_EQ(r.has(app::kRecordDistanceValid), s.distance_valid) << t;
  EXPECT_EQ(r.has(app::kRecordContact), s.contact) << t;
  EXPECT_EQ(r.has(app::kRecordCommandValid), s.command_valid) << t;
  EXPECT_EQ(std::memcmp(r.prediction, s.prediction, sizeof s.prediction), 0) << t;
  EXPECT_EQ(std::memcmp(&r.d, &s.d, sizeof s.d), 0) << t;
  EXPECT_EQ(std::memcmp(r.command, s.command, sizeof s.command), 0) << t;
}

// ---- channel layout: from the generated model's names

TEST(ChannelLayout, LoadcellIndexParsesOnlyTheBoardGroup) {
  EXPECT_EQ(app::loadcell_index_of("fc", "fc0"), 0);
  EXPECT_EQ(app::loadcell_index_of("fc", "fc8"), 8);
  EXPECT_EQ(app::loadcell_index_of("fc", "fc12"), 12);
  EXPECT_EQ(app::loadcell_index_of("fc", "fc"), -1);
  EXPECT_EQ(app::loadcell_index_of("fc", "f0"), -1);
  EXPECT_EQ(app::loadcell_index_of("fc", "fcx"), -1);
  EXPECT_EQ(app::loadcell_index_of("fc", "fc1a"), -1);
  EXPECT_EQ(app::loadcell_index_of("fc", "th0"), -1);
  EXPECT_EQ(app::loadcell_index_of("fc", ""), -1);
  EXPECT_EQ(app::loadcell_index_of("lc", "lc3"), 3);
  EXPECT_EQ(app::loadcell_index_of("lc", "fc3"), -1);
  EXPECT_EQ(app::loadcell_index_of("", "3"), -1) << "an empty group names no channel";
  EXPECT_EQ(app::loadcell_index_of("", "fc3"), -1);
}

// The layout against the model's names, read here with std::string: every
// "fc<k>" is loadcell k, everything else is the muscle state in y order.
// The hand's model (docs/architecture.md §2) has 9 loadcells and 18 other channels.
TEST(ChannelLayout, FollowsTheGeneratedModelsChannelNames) {
  using L = app::ChannelLayout<Q>;
  EXPECT_EQ(L::kLoadcells, 9);
  EXPECT_EQ(L::kMuscleY, 18);
  std::vector<int> muscle;
  for (int i = 0; i < Q::kY; ++i) {
    const std::string name = Q::kYNames[i];
    if (name.rfind("fc", 0) == 0) {
      const int k = std::stoi(name.substr(2));
      ASSERT_LT(k, L::kLoadcells) << name;
      EXPECT_EQ(L::kLoadcellY[k], i) << name;
    } else {
      muscle.push_back(i);
    }
  }
  ASSERT_EQ(muscle.size(), static_cast<std::size_t>(L::kMuscleY));
  for (int j = 0; j < L::kMuscleY; ++j) EXPECT_EQ(L::kMuscleYChannel[j], muscle[j]) << j;
  EXPECT_EQ(std::string(Q::kYNames[L::kMuscleYChannel[0]]), "l0");
  EXPECT_EQ(std::string(Q::kYNames[L::kMuscleYChannel[L::kMuscleY - 1]]), "th1");
  // The payload sizes follow: 4 (18 + 8) and 4 * 9.
  EXPECT_EQ(PayloadSizes<Q>::kMuscleState, 104u);
  EXPECT_EQ(PayloadSizes<Q>::kTareAck, 36u);
  EXPECT_EQ(PayloadSizes<Q>::kPeriodResult, 23u + 4u * (9 + 1 + 27 + 8) + 16u);
}

TEST(ChannelLayout, SplitThenAssembleIsTheSameFrame) {
  const firmware::SensorFrame<Q> frame = synthetic_frame<Q>(3);
  app::MuscleState<Q> muscle;
  float loadcells[app::ChannelLayout<Q>::kLoadcells];
  app::split_frame<Q>(frame, muscle, loadcells);
  firmware::SensorFrame<Q> back{};
  app::assemble_frame<Q>(muscle, loadcells, back);
  EXPECT_EQ(std::memcmp(&back, &frame, sizeof frame), 0);
}

// The 0x88 payload: every field at its documented offset (little-endian),
// and the decoder refuses a wrong size, an unknown mode, unknown flag bits
// or a recognition naming a state the PB table does not have.
TEST(PeriodResultPayload, LayoutAndDecoderChecks) {
  app::PeriodRecord<Q> r;
  r.sequence = 0x01020304u;
  r.period = 0x05060708u;
  r.mode = Mode::kControl;
  r.flags = app::kRecordStepped | app::kRecordOverrun | app::kRecordRecognition;
  r.muscle_state_age = 3;
  r.overruns = 4;
  r.missed_periods = 5;
  for (int k = 0; k < app::ChannelLayout<Q>::kLoadcells; ++k) r.loadcells_N[k] = 0.5f * static_cast<float>(k);
  r.d = 17.25f;
  for (int i = 0; i < Q::kY; ++i) r.prediction[i] = static_cast<float>(i);
  for (int i = 0; i < Q::kU; ++i) r.command[i] = -static_cast<float>(i);
  r.adapt_updates = 0x0A0B0C0Du;
  r.recognized_state = Q::kStates - 1;
  r.recognized_distance = 0.125f;
  r.other_object_state = 2;
  r.other_object_distance = 0.75f;
  Bytes p(PayloadSizes<Q>::kPeriodResult);
  ASSERT_EQ(encode_period_result<Q>(r, p), p.size());
  const Bytes head = {0x04, 0x03, 0x02, 0x01, 0x08, 0x07, 0x06, 0x05, 0x02, 0x10, 0x03,
                      0x03, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x05, 0x00, 0x00, 0x00};
  EXPECT_EQ(Bytes(p.begin(), p.begin() + 23), head);
  const auto f32_at = [&](std::size_t offset) {
    std::uint32_t u = 0;
    for (int k = 0; k < 4; ++k) u |= static_cast<std::uint32_t>(p[offset + k]) << (8 * k);
    return std::bit_cast<float>(u);
  };
  constexpr std::size_t kLc = app::ChannelLayout<Q>::kLoadcells;
  EXPECT_EQ(f32_at(23 + 4 * 2), 1.0f) << "loadcells[2]";
  EXPECT_EQ(f32_at(23 + 4 * kLc), 17.25f) << "d";
  EXPECT_EQ(f32_at(23 + 4 * (kLc + 1) + 4 * 26), 26.0f) << "prediction[26]";
  EXPECT_EQ(f32_at(23 + 4 * (kLc + 1 + Q::kY) + 4 * 7), -7.0f) << "command[7]";
  constexpr std::size_t kAdapt = 23 + 4 * (kLc + 1 + Q::kY + Q::kU);
  EXPECT_EQ(Bytes(p.begin() + kAdapt, p.begin() + kAdapt + 6),
            (Bytes{0x0D, 0x0C, 0x0B, 0x0A, static_cast<std::uint8_t>(Q::kStates - 1), 0x00}))
      << "adapt_updates, recognized_state";
  EXPECT_EQ(f32_at(kAdapt + 6), 0.125f) << "recognized_distance";
  EXPECT_EQ(p[kAdapt + 10], 2) << "other_object_state";
  EXPECT_EQ(f32_at(kAdapt + 12), 0.75f) << "other_object_distance";
  EXPECT_EQ(kAdapt + 16, p.size());

  app::PeriodRecord<Q> back;
  ASSERT_TRUE(decode_period_result<Q>(p, back));
  Bytes again(p.size());
  encode_period_result<Q>(back, again);
  EXPECT_EQ(again, p);

  Bytes bad_mode = p;
  bad_mode[8] = 3;
  EXPECT_FALSE(decode_period_result<Q>(bad_mode, back));
  Bytes bad_flags = p;
  bad_flags[10] = 0x04;  // bit 10
  EXPECT_FALSE(decode_period_result<Q>(bad_flags, back));
  Bytes bad_state = p;
  bad_state[kAdapt + 4] = static_cast<std::uint8_t>(Q::kStates);  // one past the PB table
  EXPECT_FALSE(decode_period_result<Q>(bad_state, back));
  Bytes bad_other = p;
  bad_other[kAdapt + 10] = 0xFE;
  bad_other[kAdapt + 11] = 0xFF;  // 0xFFFE: neither a row nor "none"
  EXPECT_FALSE(decode_period_result<Q>(bad_other, back));
  Bytes no_other = p;
  no_other[kAdapt + 10] = 0xFF;
  no_other[kAdapt + 11] = 0xFF;  // kRecordNoOtherObject
  EXPECT_TRUE(decode_period_result<Q>(no_other, back));
  EXPECT_EQ(back.other_object_state, app::kRecordNoOtherObject);
  Bytes unflagged = bad_state;
  unflagged[10] = 0x01;  // recognition flag clear: the fields are not read as a state
  EXPECT_TRUE(decode_period_result<Q>(unflagged, back));
  EXPECT_FALSE(decode_period_result<Q>(Bytes(p.begin(), p.end() - 1), back));
}

// Nothing assumes the hand's layout: the hand's model under other channel
// names (same weights, so the runtime works as before). With the loadcells
// named in another order and place, loadcell k still lands on "fc<k>"; with
// no loadcell channel at all, the muscle state is the whole y and the loop
// still gives the host-driven results bit for bit.
struct ShuffledLoadcells : Q {
  static constexpr const char* const kYNames[Q::kY] = {
      "fc2", "l0", "l1", "l2", "l3", "l4", "l5", "l6", "l7", "f0", "f1", "f2", "f3", "f4",
      "fc0", "f5", "f6", "f7", "fc1", "fc3", "fc4", "fc5", "fc6", "fc7", "fc8", "th0", "th1"};
};
// The board group is the model's (its profile's), not the hand's "fc".
struct OtherBoardGroup : Q {
  static constexpr char kBoardGroup[] = "f";
};
struct NoBoardGroup : Q {
  static constexpr char kBoardGroup[] = "";
};
struct NoLoadcells : Q {
  static constexpr const char* const kYNames[Q::kY] = {
      "q0",  "q1",  "q2",  "q3",  "q4",  "q5",  "q6",  "q7",  "q8",  "q9",  "q10", "q11", "q12", "q13",
      "q14", "q15", "q16", "q17", "q18", "q19", "q20", "q21", "q22", "q23", "q24", "q25", "q26"};
};

TEST(ChannelLayout, TakesTheSplitFromTheNamesNotFromTheHand) {
  using S = app::ChannelLayout<ShuffledLoadcells>;
  EXPECT_EQ(S::kLoadcells, 9);
  EXPECT_EQ(S::kLoadcellY[0], 14);
  EXPECT_EQ(S::kLoadcellY[1], 18);
  EXPECT_EQ(S::kLoadcellY[2], 0);
  EXPECT_EQ(S::kLoadcellY[8], 24);
  EXPECT_EQ(S::kMuscleYChannel[0], 1);
  EXPECT_EQ(S::kMuscleYChannel[13], 15);
  using N = app::ChannelLayout<NoLoadcells>;
  EXPECT_EQ(N::kLoadcells, 0);
  EXPECT_EQ(N::kMuscleY, Q::kY);
  EXPECT_EQ(PayloadSizes<NoLoadcells>::kTareAck, 0u);
  EXPECT_EQ(PayloadSizes<NoLoadcells>::kPeriodResult, 23u + 4u * (1 + 27 + 8) + 16u);
  using G = app::ChannelLayout<OtherBoardGroup>;  // f0..f7 on the board, fc* over the link
  EXPECT_EQ(G::kLoadcells, 8);
  EXPECT_EQ(std::string(Q::kYNames[G::kLoadcellY[0]]), "f0");
  EXPECT_EQ(app::ChannelLayout<NoBoardGroup>::kLoadcells, 0);
}

template <firmware::GeneratedModel M>
void check_loop_matches_sensor_frames(int frames, int control_from);

TEST(PeriodLoop, AModelWithoutLoadcellsStillMatchesSensorFrames) {
  check_loop_matches_sensor_frames<NoLoadcells>(10, 100);
}

// ---- the loop against host-driven sensor frames, over the link

// Device A: muscle states over the link + loadcell readings into the loop,
// one period per frame, the record fetched over the link. Device B: the same
// frames as host-driven sensor frames (0x02). Through detect and control
// mode, every record equals B's step result bit for bit, and at the end the
// two runtimes are equal byte for byte.
template <firmware::GeneratedModel M>
void check_loop_matches_sensor_frames(int frames, int control_from) {
  ZeroedDevice<M> a, b;
  LinkClient<M> ca, cb;
  Bytes storage;
  for (int t = 0; t < frames; ++t) {
    if (t == control_from) {
      exchange(a, ca, wire_of([&](auto w) { return ca.set_mode(Mode::kControl, w); }), MessageType::kSetModeAck,
               storage);
      exchange(b, cb, wire_of([&](auto w) { return cb.set_mode(Mode::kControl, w); }), MessageType::kSetModeAck,
               storage);
    }
    const firmware::SensorFrame<M> frame = synthetic_frame<M>(t);
    app::MuscleState<M> muscle;
    Reading<M> reading;
    split<M>(frame, muscle, reading);

    const Reply ack = exchange(a, ca, wire_of([&](auto w) { return ca.muscle_state(muscle, w); }),
                               MessageType::kMuscleStateAck, storage);
    std::uint32_t first_record = 0;
    ASSERT_TRUE(decode_muscle_state_ack(ack.payload, first_record));
    EXPECT_EQ(first_record, static_cast<std::uint32_t>(t + 1)) << "the next record uses it";
    a->link.loop().run_period(reading, 0);
    a->link.loop().end_period(10, 100);
    const app::PeriodRecord<M> record = request_record(a, ca);

    const Reply step = exchange(b, cb, wire_of([&](auto w) { return cb.sensor_frame(frame, w); }),
                                MessageType::kStepResult, storage);
    firmware::StepResult<M> host;
    ASSERT_TRUE(decode_step_result<M>(step.payload, host));

    EXPECT_EQ(record.sequence, static_cast<std::uint32_t>(t + 1));
    EXPECT_EQ(record.flags & ~(app::kRecordPredictionValid | app::kRecordDistanceValid | app::kRecordContact |
                               app::kRecordCommandValid),
              app::kRecordStepped)
        << "fresh, with loadcells, no overrun: " << t;
    EXPECT_EQ(record.muscle_state_age, 0u);
    EXPECT_EQ(record.mode, t >= control_from ? Mode::kControl : Mode::kDetect);
    EXPECT_EQ(std::memcmp(record.loadcells_N, reading.newtons, sizeof reading.newtons), 0) << t;
    expect_record_is_step<M>(record, host, t);
    if (t >= M::kDetectSteps + 1) {
      EXPECT_TRUE(record.has(app::kRecordPredictionValid)) << t;
    }
    if (t >= control_from + 1) {
      EXPECT_TRUE(record.has(app::kRecordCommandValid)) << t;
    }
  }
  EXPECT_EQ(std::memcmp(&a->runtime, &b->runtime, sizeof a->runtime), 0) << "runtime bytes differ";
}

// On-device adaptation in the loop: adaptation switched on over the link
// (0x09), the loop's record of every period carries the runtime's own
// adaptation count and recognition, bit for bit: a runtime adapting with the
// same settings on the same frames, stepped directly, is the reference.
// Every 8th window, 2 per period: the first PB update comes a few periods
// after the 100th window, so the recognition flag must appear, and stay.
TEST(PeriodLoop, RecordsCarryTheAdaptingRuntimesRecognition) {
  ZeroedDevice<Q> a;
  LinkClient<Q> ca;
  Bytes storage;
  auto direct = std::make_unique<firmware::HadynetRuntime<Q>>();
  typename firmware::PbAdapter<Q>::Settings settings = direct->adapter().settings();
  settings.window_stride = 8;
  settings.windows_per_period = 2;
  ASSERT_TRUE(direct->set_adapt_settings(settings));
  direct->set_adapting(true);
  exchange(a, ca, wire_of([&](auto w) { return ca.adapt({AdaptAction::kOn, 8, 2}, w); }), MessageType::kAdaptStatus,
           storage);
  const int frames = 100 + Q::kTrainSteps + 2 + 24;
  int first_recognition = -1;
  for (int t = 0; t < frames; ++t) {
    const firmware::SensorFrame<Q> frame = synthetic_frame<Q>(t);
    app::MuscleState<Q> muscle;
    Reading<Q> reading;
    split<Q>(frame, muscle, reading);
    exchange(a, ca, wire_of([&](auto w) { return ca.muscle_state(muscle, w); }), MessageType::kMuscleStateAck,
             storage);
    a->link.loop().run_period(reading, 0);
    a->link.loop().end_period(10, 100);
    const app::PeriodRecord<Q> record = request_record(a, ca);
    const firmware::StepResult<Q> want = direct->step(frame);
    expect_record_is_step<Q>(record, want, t);
    EXPECT_EQ(record.adapt_updates, want.adapt_updates) << t;
    const bool named = want.adapt_valid && want.recognition.valid;
    ASSERT_EQ(record.has(app::kRecordRecognition), named) << t;
    if (!named) {
      EXPECT_EQ(record.recognized_state, 0) << t;
      EXPECT_EQ(record.other_object_state, 0) << t;
      EXPECT_EQ(record.recognized_distance, 0.0f) << t;
      continue;
    }
    if (first_recognition < 0) first_recognition = t;
    EXPECT_EQ(record.recognized_state, want.recognition.state) << t;
    EXPECT_EQ(std::memcmp(&record.recognized_distance, &want.recognition.distance, sizeof(float)), 0) << t;
    EXPECT_EQ(record.other_object_state, want.recognition.other_state < 0 ? app::kRecordNoOtherObject
                                                                          : want.recognition.other_state)
        << t;
    EXPECT_EQ(std::memcmp(&record.other_object_distance, &want.recognition.other_distance, sizeof(float)), 0) << t;
  }
  EXPECT_GE(first_recognition, 100) << "no PB update before the 100th window";
  EXPECT_LT(first_recognition, frames - 1) << "no recognition in " << frames << " periods";
}

TEST(PeriodLoop, MuscleStatesAndLoadcellsMatchSensorFramesBitForBitQ15) {
  check_loop_matches_sensor_frames<Q>(20, 12);
}
TEST(PeriodLoop, MuscleStatesAndLoadcellsMatchSensorFramesBitForBitF32) {
  check_loop_matches_sensor_frames<F>(12, 9);
}

// ---- the loop on its own (the tests are the board)

// The object representation of `v` (a runtime in zeroed memory: padding
// included, so equal states compare equal).
template <class T>
std::vector<unsigned char> bytes_of(const T& v) {
  const auto* p = reinterpret_cast<const unsigned char*>(&v);
  return std::vector<unsigned char>(p, p + sizeof v);
}

struct LoopUnderTest {
  std::unique_ptr<ZeroedDevice<Q>> device = std::make_unique<ZeroedDevice<Q>>();
  std::unique_ptr<ZeroedDevice<Q>> twin = std::make_unique<ZeroedDevice<Q>>();  // stepped directly
  app::PeriodLoop<Q>& loop() { return (*device)->link.loop(); }
};

// Every period without a new muscle state steps with the newest one it has
// (the same frame a host would build from it) and says so: stale flag, age
// in records. A new muscle state is fresh again; of two in one period the
// newer one counts.
TEST(PeriodLoop, StaleMuscleStateIsFlaggedNotSilentlyReused) {
  LoopUnderTest u;
  app::MuscleState<Q> m1, m2, m3;
  Reading<Q> r[6];
  for (int t = 0; t < 6; ++t) {
    app::MuscleState<Q> m;
    split<Q>(synthetic_frame<Q>(t), m, r[t]);
    if (t == 0) m1 = m;
    if (t == 3) m2 = m;
    if (t == 4) m3 = m;
  }
  const auto step_twin = [&](const app::MuscleState<Q>& m, const Reading<Q>& reading) {
    firmware::SensorFrame<Q> frame;
    app::assemble_frame<Q>(m, reading.newtons, frame);
    return (*u.twin)->runtime.step(frame);
  };

  EXPECT_EQ(u.loop().receive_muscle_state(m1), 1u);
  const app::PeriodRecord<Q> fresh = u.loop().run_period(r[0], 0);
  EXPECT_FALSE(fresh.has(app::kRecordStaleMuscleState));
  EXPECT_EQ(fresh.muscle_state_age, 0u);
  expect_record_is_step<Q>(fresh, step_twin(m1, r[0]), 0);

  for (int t = 1; t <= 2; ++t) {
    const app::PeriodRecord<Q> stale = u.loop().run_period(r[t], 0);
    EXPECT_TRUE(stale.has(app::kRecordStaleMuscleState)) << t;
    EXPECT_EQ(stale.muscle_state_age, static_cast<std::uint32_t>(t)) << "records since it arrived";
    expect_record_is_step<Q>(stale, step_twin(m1, r[t]), t);
  }

  EXPECT_EQ(u.loop().receive_muscle_state(m2), 4u);
  EXPECT_EQ(u.loop().receive_muscle_state(m3), 4u);  // same period: replaces m2
  const app::PeriodRecord<Q> again = u.loop().run_period(r[3], 0);
  EXPECT_FALSE(again.has(app::kRecordStaleMuscleState));
  EXPECT_EQ(again.muscle_state_age, 0u);
  expect_record_is_step<Q>(again, step_twin(m3, r[3]), 3);
  EXPECT_EQ(std::memcmp(&(*u.device)->runtime, &(*u.twin)->runtime, sizeof(firmware::HadynetRuntime<Q>)), 0);
}

// No muscle state (never received, or forgotten after a host-driven sensor
// frame or a reset): every period reports it and the runtime stays byte for
// byte as it was; the records still count and carry the loadcells.
TEST(PeriodLoop, WithoutMuscleStateTheLoopReportsAndDoesNotStep) {
  LoopUnderTest u;
  LinkClient<Q> client;
  Bytes storage;
  app::MuscleState<Q> m;
  Reading<Q> reading;
  split<Q>(synthetic_frame<Q>(0), m, reading);

  const auto expect_idle_period = [&](std::uint32_t sequence) {
    const std::vector<unsigned char> before = bytes_of((*u.device)->runtime);
    const app::PeriodRecord<Q> r = u.loop().run_period(reading, 0);
    EXPECT_EQ(r.sequence, sequence);
    EXPECT_EQ(r.flags, app::kRecordNoMuscleState) << "not stepped, nothing valid";
    EXPECT_EQ(std::memcmp(r.loadcells_N, reading.newtons, sizeof reading.newtons), 0);
    const float zeros[Q::kY] = {};
    EXPECT_EQ(std::memcmp(r.prediction, zeros, sizeof r.prediction), 0);
    EXPECT_EQ(bytes_of((*u.device)->runtime), before) << "the runtime stepped";
  };

  expect_idle_period(1);
  expect_idle_period(2);
  EXPECT_FALSE(u.loop().has_muscle_state());

  // A muscle state arms the loop; a host-driven sensor frame disarms it.
  exchange(*u.device, client, wire_of([&](auto w) { return client.muscle_state(m, w); }),
           MessageType::kMuscleStateAck, storage);
  EXPECT_TRUE(u.loop().run_period(reading, 0).has(app::kRecordStepped));
  exchange(*u.device, client, wire_of([&](auto w) { return client.muscle_state(m, w); }),
           MessageType::kMuscleStateAck, storage);
  exchange(*u.device, client, wire_of([&](auto w) { return client.sensor_frame(synthetic_frame<Q>(1), w); }),
           MessageType::kStepResult, storage);
  expect_idle_period(4);
  // ... and so does a reset.
  exchange(*u.device, client, wire_of([&](auto w) { return client.muscle_state(m, w); }),
           MessageType::kMuscleStateAck, storage);
  exchange(*u.device, client, wire_of([&](auto w) { return client.reset(w); }), MessageType::kResetAck, storage);
  expect_idle_period(5);
}

// A board without a reading (no loadcells, or no scan yet): no step, flagged.
TEST(PeriodLoop, WithoutLoadcellReadingTheLoopDoesNotStep) {
  LoopUnderTest u;
  app::MuscleState<Q> m;
  Reading<Q> reading;
  split<Q>(synthetic_frame<Q>(0), m, reading);
  u.loop().receive_muscle_state(m);
  const std::vector<unsigned char> before = bytes_of((*u.device)->runtime);
  const app::PeriodRecord<Q> r = u.loop().run_period(Reading<Q>{}, 0);
  EXPECT_EQ(r.flags, app::kRecordNoLoadcells);
  EXPECT_EQ(bytes_of((*u.device)->runtime), before) << "the runtime stepped";
}

// Tare over the link: refused before any reading (not ready, nothing
// changed); then the offsets are the latest reading, so that reading enters
// the frame as exactly 0 N and another one as (reading - offset), the one
// float subtraction the contract names; clear returns to the raw readings.
TEST(PeriodLoop, TareZeroesTheOffsetsAtTheLatestReading) {
  LoopUnderTest u;
  LinkClient<Q> client;
  Bytes storage;
  app::MuscleState<Q> m;
  Reading<Q> r1, r2;
  split<Q>(synthetic_frame<Q>(0), m, r1);
  split<Q>(synthetic_frame<Q>(5), m, r2);
  constexpr int kN = app::ChannelLayout<Q>::kLoadcells;

  {
    const Bytes reply = u.device->send_one(wire_of([&](auto w) { return client.tare(TareAction::kZero, w); }));
    const Reply r = client.accept(reply);
    ASSERT_EQ(r.type, MessageType::kError);
    ErrorReply e;
    ASSERT_TRUE(decode_error(r.payload, e));
    EXPECT_EQ(e.code, ErrorCode::kNotReady);
    const float zeros[kN] = {};
    EXPECT_EQ(std::memcmp(u.loop().tare_offsets_N(), zeros, sizeof zeros), 0);
  }

  EXPECT_EQ(std::memcmp(u.loop().run_period(r1, 0).loadcells_N, r1.newtons, sizeof r1.newtons), 0);
  const Reply ack = exchange(*u.device, client, wire_of([&](auto w) { return client.tare(TareAction::kZero, w); }),
                             MessageType::kTareAck, storage);
  float offsets[kN];
  ASSERT_TRUE(decode_tare_ack<Q>(ack.payload, offsets));
  EXPECT_EQ(std::memcmp(offsets, r1.newtons, sizeof offsets), 0) << "offsets = the reading at tare time";

  const app::PeriodRecord<Q> zeroed = u.loop().run_period(r1, 0);
  for (int k = 0; k < kN; ++k) {
    EXPECT_EQ(std::bit_cast<std::uint32_t>(zeroed.loadcells_N[k]), 0u) << "exactly +0 N, loadcell " << k;
  }

  // The tared values are what the runtime steps with.
  u.loop().receive_muscle_state(m);
  const app::PeriodRecord<Q> tared = u.loop().run_period(r2, 0);
  float expected[kN];
  for (int k = 0; k < kN; ++k) expected[k] = r2.newtons[k] - r1.newtons[k];
  EXPECT_EQ(std::memcmp(tared.loadcells_N, expected, sizeof expected), 0);
  firmware::SensorFrame<Q> frame;
  app::assemble_frame<Q>(m, expected, frame);
  expect_record_is_step<Q>(tared, (*u.twin)->runtime.step(frame), 0);

  const Reply cleared = exchange(*u.device, client,
                                 wire_of([&](auto w) { return client.tare(TareAction::kClear, w); }),
                                 MessageType::kTareAck, storage);
  ASSERT_TRUE(decode_tare_ack<Q>(cleared.payload, offsets));
  const float zeros[kN] = {};
  EXPECT_EQ(std::memcmp(offsets, zeros, sizeof zeros), 0);
  EXPECT_EQ(std::memcmp(u.loop().run_period(r2, 0).loadcells_N, r2.newtons, sizeof r2.newtons), 0);
}

// A period whose work took longer than one period is flagged and counted
// (the count carries on in later records); the board's missed boundaries
// are reported as given and added to the period index.
TEST(PeriodLoop, OverrunsAreCountedAndReported) {
  LoopUnderTest u;
  Reading<Q> reading;
  app::MuscleState<Q> m;
  split<Q>(synthetic_frame<Q>(0), m, reading);
  constexpr std::uint32_t kTicks = 5'000'000;  // 25 MHz / 5 Hz

  u.loop().end_period(kTicks + 1, kTicks);  // before any period: nothing to flag
  EXPECT_EQ(u.loop().latest().overruns, 0u);

  u.loop().run_period(reading, 0);
  u.loop().end_period(kTicks, kTicks);  // exactly one period: not an overrun
  EXPECT_FALSE(u.loop().latest().has(app::kRecordOverrun));
  EXPECT_EQ(u.loop().latest().overruns, 0u);

  u.loop().run_period(reading, 0);
  u.loop().end_period(kTicks + 1, kTicks);
  EXPECT_TRUE(u.loop().latest().has(app::kRecordOverrun));
  EXPECT_EQ(u.loop().latest().overruns, 1u);

  const app::PeriodRecord<Q> next = u.loop().run_period(reading, 2);  // the board missed 2 boundaries
  EXPECT_FALSE(next.has(app::kRecordOverrun));
  EXPECT_EQ(next.overruns, 1u);
  EXPECT_EQ(next.missed_periods, 2u);
  EXPECT_EQ(next.sequence, 3u);
  EXPECT_EQ(next.period, 5u);
  u.loop().end_period(3 * kTicks, kTicks);
  EXPECT_EQ(u.loop().latest().overruns, 2u);

  // The same over the link.
  LinkClient<Q> client;
  const app::PeriodRecord<Q> wire = request_record(*u.device, client);
  EXPECT_TRUE(wire.has(app::kRecordOverrun));
  EXPECT_EQ(wire.overruns, 2u);
  EXPECT_EQ(wire.missed_periods, 2u);
  EXPECT_EQ(wire.period, 5u);
}

// Before the first period the latest record is the empty one: sequence 0.
TEST(PeriodLoop, NoRecordBeforeTheFirstPeriod) {
  ZeroedDevice<Q> dev;
  LinkClient<Q> client;
  const app::PeriodRecord<Q> r = request_record(dev, client);
  EXPECT_EQ(r.sequence, 0u);
  EXPECT_EQ(r.flags, 0u);
}

// ---- robustness of the new messages: twins

// Device A gets each malformed request, B never does; both then run the same
// period and answer the same record request. A's error reply has the right
// code and echoes the number; runtime bytes, sequence state, tare offsets
// and the next record (which exposes the held muscle state and its age) are
// B's, exactly.
class PeriodLoopRobustness : public ::testing::Test {
 protected:
  void SetUp() override {
    client_.set_next_sequence(300);
    split<Q>(synthetic_frame<Q>(0), muscle_, reading_);
    exchange_both([&](auto w) { return client_.muscle_state(muscle_, w); });
    period_both();
    exchange_both([&](auto w) { return client_.tare(TareAction::kZero, w); });
    period_both();
  }

  template <class F>
  Bytes exchange_both(F&& build) {
    const Bytes wire = wire_of(build);
    const Bytes ra = a_.send_one(wire);
    const Bytes rb = b_.send_one(wire);
    EXPECT_EQ(ra, rb);
    EXPECT_TRUE(client_.accept(ra).ok()) << "valid request refused";
    return ra;
  }
  void period_both() {
    Reading<Q> r = reading_;
    r.newtons[0] += static_cast<float>(next_t_++);  // a new reading each period
    a_->link.loop().run_period(r, 0);
    b_->link.loop().run_period(r, 0);
  }

  void expect_rejected(const std::string& name, std::uint8_t type, const Bytes& payload, ErrorCode code,
                       std::uint16_t sequence) {
    SCOPED_TRACE(name);
    const std::vector<Bytes> replies = a_.send(encode_wire(make_frame(1, type, sequence, payload)));
    ASSERT_EQ(replies.size(), 1u);
    const Reply r = parse_reply(replies[0]);
    ASSERT_EQ(r.type, MessageType::kError);
    ErrorReply e;
    ASSERT_TRUE(decode_error(r.payload, e));
    EXPECT_EQ(e.code, code) << e.reason;
    EXPECT_EQ(e.sequence, sequence);
    expect_same_state(a_, b_);
    EXPECT_EQ(a_->link.loop().has_muscle_state(), b_->link.loop().has_muscle_state());
    EXPECT_EQ(std::memcmp(a_->link.loop().tare_offsets_N(), b_->link.loop().tare_offsets_N(),
                          sizeof(a_->link.loop().tare_offsets_N())),
              0);
    period_both();
    const Bytes ra = exchange_both([&](auto w) { return client_.period_result_request(w); });
    app::PeriodRecord<Q> record;
    ASSERT_TRUE(decode_period_result<Q>(parse_reply(ra).payload, record));
    EXPECT_TRUE(record.has(app::kRecordStepped));
    expect_same_state(a_, b_);
  }
  void expect_rejected(const std::string& name, std::uint8_t type, const Bytes& payload, ErrorCode code) {
    expect_rejected(name, type, payload, code, client_.next_sequence());
  }

  ZeroedDevice<Q> a_, b_;
  LinkClient<Q> client_;
  app::MuscleState<Q> muscle_;
  Reading<Q> reading_;
  int next_t_ = 1;
};

TEST_F(PeriodLoopRobustness, MalformedMuscleStateTareAndResultRequests) {
  Bytes good(PayloadSizes<Q>::kMuscleState);
  app::MuscleState<Q> other;
  Reading<Q> unused;
  split<Q>(synthetic_frame<Q>(9), other, unused);
  ASSERT_EQ(encode_muscle_state<Q>(other, good), good.size());
  const Bytes short_state(good.begin(), good.end() - 1);
  const Bytes long_state = good + Bytes{0x00};

  expect_rejected("muscle state one byte short", 0x06, short_state, ErrorCode::kBadPayloadLength);
  expect_rejected("muscle state one byte long", 0x06, long_state, ErrorCode::kBadPayloadLength);
  expect_rejected("muscle state empty", 0x06, {}, ErrorCode::kBadPayloadLength);
  expect_rejected("muscle state as a sensor frame",
                  0x06, Bytes(PayloadSizes<Q>::kSensorFrame, 0x11), ErrorCode::kBadPayloadLength);
  expect_rejected("tare empty", 0x07, {}, ErrorCode::kBadPayloadLength);
  expect_rejected("tare two bytes", 0x07, {0x00, 0x00}, ErrorCode::kBadPayloadLength);
  expect_rejected("tare action 2", 0x07, {0x02}, ErrorCode::kBadValue);
  expect_rejected("tare action 255", 0x07, {0xFF}, ErrorCode::kBadValue);
  expect_rejected("period request with payload", 0x08, {0x00}, ErrorCode::kBadPayloadLength);
  // One ahead of the expected number (each case's valid follow-up advances it).
  const auto ahead = [&] { return static_cast<std::uint16_t>(client_.next_sequence() + 1); };
  expect_rejected("muscle state out of order", 0x06, good, ErrorCode::kOutOfOrder, ahead());
  expect_rejected("tare out of order", 0x07, {0x01}, ErrorCode::kOutOfOrder, ahead());
  expect_rejected("period request out of order", 0x08, {}, ErrorCode::kOutOfOrder, ahead());
}

TEST(PeriodLoopRobustnessFresh, TareBeforeAnyReadingIsNotReadyAndDoesNotSynchronise) {
  ZeroedDevice<Q> a;
  const std::vector<Bytes> replies = a.send(encode_wire(make_frame(1, 0x07, 77, {0x00})));
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(parse_reply(replies[0]).type, MessageType::kError);
  EXPECT_FALSE(a->link.dispatcher().synchronised());
  // Clearing needs no reading.
  EXPECT_EQ(parse_reply(a.send_one(encode_wire(make_frame(1, 0x07, 77, {0x01})))).type, MessageType::kTareAck);
}

}  // namespace
}  // namespace hadynet::link
