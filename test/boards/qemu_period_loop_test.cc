// The firmware's autonomous 5 Hz loop in the mps2-an386 image under QEMU
// (firmware/app/period_loop.h, docs/protocol.md 0x06..0x08): SysTick runs
// the periods, the board's synthetic loadcells
// (boards/mps2-an386/synthetic_loadcells.h) are the readings, muscle states
// arrive over UART0, and the records are polled over the link.
//
// Proof by a twin: the host replays every period the device ran with the
// same q15 runtime (reference kernels) on the frame the contract says the
// device built (the newest muscle state sent before that record, the
// synthetic scan sequence - 1 minus the tare offsets), and every record it
// sees must equal the twin's step bit for bit (tolerance zero: same code,
// same inputs; q15 is bit-identical on host and MCU). The twin does not
// depend on how the emulator's timing falls: a record the poll did not see
// is still replayed, and which muscle state a record used follows from the
// acks' "first record" numbers.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "boards/mps2-an386/synthetic_loadcells.h"
#include "firmware/app/channel_layout.h"
#include "firmware/app/period_record.h"
#include "firmware/app/synthetic_frames.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/link/link_client.h"
#include "firmware/link/messages.h"
#include "firmware/link/stream_decoder.h"
#include "hadynet_model_q15.h"
#include "tools/link/link_session.h"
#include "tools/link/qemu_process.h"

namespace hadynet {
namespace {

using Q = model_q15::Model;
using Layout = app::ChannelLayout<Q>;
using Record = app::PeriodRecord<Q>;
// (The image checks its model's loadcells against its board: firmware/app/image_checks.h.)

class QemuPeriodLoop : public ::testing::Test {
 protected:
  void SetUp() override {
    qemu_ = std::make_unique<tools::QemuProcess>(
        tools::QemuOptions{"qemu-system-arm", "mps2-an386", HADYNET_FIRMWARE_IMAGE, false, "", {}});
    tools::LinkSession<Q> session(qemu_->link());
    session.connect();  // reset: the loop holds no muscle state
    client_.set_next_sequence(1);
    std::uint8_t buffer[256];
    while (qemu_->link().read(buffer, 500) > 0) {  // late acks of a repeated reset
    }
  }

  // Sends one request; returns its success reply (fails on anything else).
  link::Reply exchange(std::size_t wire_size, link::MessageType expected) {
    EXPECT_GT(wire_size, 0u);
    qemu_->link().write(std::span<const std::uint8_t>(wire_, wire_size));
    std::uint8_t buffer[256];
    while (true) {
      const std::size_t n = qemu_->link().read(buffer, 10000);
      if (n == 0) throw tools::LinkError("no reply");
      for (std::size_t i = 0; i < n; ++i) {
        if (rx_.push(buffer[i]) != link::StreamDecoder::Event::kFrame) continue;
        reply_.assign(rx_.frame().begin(), rx_.frame().end());
        const link::Reply r = client_.accept(reply_);
        if (r.type == link::MessageType::kError) {
          link::ErrorReply e;
          link::decode_error(r.payload, e);
          ADD_FAILURE() << "error reply " << static_cast<int>(e.code) << ": " << e.reason;
        }
        EXPECT_EQ(r.type, expected);
        return r;
      }
    }
  }

  Record latest() {
    const link::Reply r = exchange(client_.period_result_request(wire_), link::MessageType::kPeriodResult);
    Record record;
    EXPECT_TRUE(link::decode_period_result<Q>(r.payload, record));
    return record;
  }

  // Polls until the device has run record `sequence` (or a later one).
  Record wait_for(std::uint32_t sequence) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (true) {
      const Record r = latest();
      if (r.sequence >= sequence) return r;
      if (std::chrono::steady_clock::now() > deadline) throw tools::LinkError("the loop stopped running periods");
      std::this_thread::sleep_for(std::chrono::milliseconds(15));
    }
  }

  std::uint32_t send_muscle_state(const app::MuscleState<Q>& m) {
    const link::Reply r = exchange(client_.muscle_state(m, wire_), link::MessageType::kMuscleStateAck);
    std::uint32_t first_record = 0;
    EXPECT_TRUE(link::decode_muscle_state_ack(r.payload, first_record));
    sent_.push_back({first_record, m});
    return first_record;
  }

  // The twin runs every record up to `seen` and compares `seen` with it.
  void replay_and_compare(const Record& seen) {
    while (replayed_ < seen.sequence) {
      const std::uint32_t s = ++replayed_;
      const Sent* used = nullptr;
      for (const Sent& m : sent_) {
        if (m.first_record <= s) used = &m;
      }
      float loadcells[Layout::kLoadcells];
      board::mps2::synthetic_loadcells(s - 1, loadcells);  // scan n in period n + 1
      if (s >= tare_from_) {
        for (int k = 0; k < Layout::kLoadcells; ++k) loadcells[k] = loadcells[k] - offsets_N_[k];
      }
      if (used == nullptr) {  // no muscle state: nothing stepped
        if (s == seen.sequence) {
          EXPECT_EQ(seen.flags, app::kRecordNoMuscleState) << "record " << s;
        }
        continue;
      }
      firmware::SensorFrame<Q> frame;
      app::assemble_frame<Q>(used->state, loadcells, frame);
      const firmware::StepResult<Q> host = twin_->step(frame);
      if (s != seen.sequence) continue;
      SCOPED_TRACE("record " + std::to_string(s));
      EXPECT_EQ(std::memcmp(seen.loadcells_N, loadcells, sizeof loadcells), 0) << "synthetic scan, tared";
      EXPECT_TRUE(seen.has(app::kRecordStepped));
      EXPECT_FALSE(seen.has(app::kRecordNoLoadcells));
      EXPECT_EQ(seen.muscle_state_age, s - used->first_record);
      EXPECT_EQ(seen.has(app::kRecordStaleMuscleState), s != used->first_record);
      EXPECT_EQ(seen.has(app::kRecordPredictionValid), host.prediction_valid);
      EXPECT_EQ(seen.has(app::kRecordDistanceValid), host.distance_valid);
      EXPECT_EQ(seen.has(app::kRecordContact), host.contact);
      EXPECT_EQ(seen.has(app::kRecordCommandValid), host.command_valid);
      EXPECT_EQ(std::memcmp(seen.prediction, host.prediction, sizeof host.prediction), 0);
      EXPECT_EQ(std::memcmp(&seen.d, &host.d, sizeof host.d), 0);
      EXPECT_EQ(std::memcmp(seen.command, host.command, sizeof host.command), 0);
      EXPECT_EQ(seen.period, seen.sequence + seen.missed_periods);
      ++compared_;
      if (seen.has(app::kRecordStaleMuscleState)) ++compared_stale_;
      if (seen.has(app::kRecordPredictionValid)) ++compared_valid_;
    }
  }

  struct Sent {
    std::uint32_t first_record;
    app::MuscleState<Q> state;
  };

  std::unique_ptr<tools::QemuProcess> qemu_;
  std::unique_ptr<firmware::HadynetRuntime<Q>> twin_ = std::make_unique<firmware::HadynetRuntime<Q>>();
  link::LinkClient<Q> client_;
  link::StreamDecoder rx_;
  std::vector<std::uint8_t> reply_;
  std::uint8_t wire_[link::kMaxWireFrame] = {};
  std::vector<Sent> sent_;
  float offsets_N_[Layout::kLoadcells] = {};
  std::uint32_t tare_from_ = UINT32_MAX;  // first record with the offsets subtracted
  std::uint32_t replayed_ = 0;
  int compared_ = 0, compared_stale_ = 0, compared_valid_ = 0;
};

// Detect mode (the default after reset; a detect period is ~0.5 M
// instructions, far inside the period under QEMU): one muscle state per
// period, two periods without one (stale), then a tare.
TEST_F(QemuPeriodLoop, MuscleStatesAndSyntheticLoadcellsMatchTheHostBitForBit) {
  // Before any muscle state: records run, nothing steps.
  const Record idle = wait_for(1);
  EXPECT_EQ(idle.flags & app::kRecordNoMuscleState, app::kRecordNoMuscleState);
  EXPECT_FALSE(idle.has(app::kRecordStepped));
  replay_and_compare(idle);

  app::SyntheticFrames<Q> frames(11);
  constexpr int kPeriods = 16;
  for (int t = 0; t < kPeriods; ++t) {
    firmware::SensorFrame<Q> frame;
    frames.next(frame);
    app::MuscleState<Q> m;
    float unused[Layout::kLoadcells];
    app::split_frame<Q>(frame, m, unused);
    std::uint32_t target = replayed_ + 1;
    if (t != 9 && t != 10) target = send_muscle_state(m);  // t = 9, 10: none (stale)
    if (t == 13) {  // tare: offsets = the reading of the latest period when it arrives
      const link::Reply r = exchange(client_.tare(link::TareAction::kZero, wire_), link::MessageType::kTareAck);
      ASSERT_TRUE(link::decode_tare_ack<Q>(r.payload, offsets_N_));
      // They must be exactly one synthetic scan: that of the record that was
      // the latest then (record r reads scan r - 1); the records after it
      // are tared. Look among the last few (a period may have run since).
      const Record now = latest();
      for (std::uint32_t rec = now.sequence; rec + 3 > now.sequence && rec >= 1; --rec) {
        float scan[Layout::kLoadcells];
        board::mps2::synthetic_loadcells(rec - 1, scan);
        if (std::memcmp(offsets_N_, scan, sizeof scan) == 0) {
          tare_from_ = rec + 1;
          break;
        }
      }
      ASSERT_NE(tare_from_, UINT32_MAX) << "tare offsets are not the latest reading";
    }
    replay_and_compare(wait_for(target));
  }
  EXPECT_GE(compared_, kPeriods - 2) << "records compared with the twin";
  EXPECT_GE(compared_stale_, 2) << "stale records compared";
  EXPECT_GE(compared_valid_, 5) << "records with a valid prediction compared";
}

}  // namespace
}  // namespace hadynet
