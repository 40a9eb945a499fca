// `hadynet monitor` (this build's executable, hidapi's libusb backend) as a
// child process against the hand on the testbed, while this thread
// publishes telemetry: records in order, the CSV it writes read back with
// the project's log reader (datalog/log_reader.h), drops from a slow
// reader equal to the gaps actually received, and HID faults.
#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "datalog/log_reader.h"
#include "test/usb_host/child_process.h"
#include "test/usb_host/hand_device.h"
#include "test/usb_host/test_records.h"
#include "test/usb_host/usb_testbed.h"

namespace hadynet::usb::host_testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr std::uint8_t kHidIn = 0x83;
constexpr std::size_t kReportsPerRecord = 4;  // docs/usb.md: the hand's model, 4 reports per period
// --duration of the monitor run: long enough for the child to start
// (~0.2 s) and take every record (~ms each here); the test waits for it.
constexpr const char* kDurationS = "2.5";
// Tolerance of the child's run: --duration plus start-up and file writing;
// 20 s only catches a hang.
constexpr auto kChildTimeout = 20s;

// "hadynet monitor: R periods received, D dropped (sequence gaps), B malformed reports, ..."
struct Summary {
  bool found = false;
  unsigned long long received = 0, dropped = 0, malformed = 0, incomplete = 0;
};

Summary summary(const std::string& err) {
  Summary s;
  const std::size_t at = err.find(" periods received, ");
  if (at == std::string::npos) return s;
  const std::size_t line = err.rfind("hadynet monitor: ", at);
  s.found = std::sscanf(err.c_str() + line,
                        "hadynet monitor: %llu periods received, %llu dropped (sequence gaps), %llu malformed reports, "
                        "%llu incomplete",
                        &s.received, &s.dropped, &s.malformed, &s.incomplete) == 4;
  return s;
}

// Every row of OUT, OUT-2, ... (monitor cuts the stream into segments at
// gaps), as the sequence numbers of finite_record(): period = sequence + 2.
struct CsvRows {
  std::vector<std::uint32_t> sequences;
  std::vector<datalog::LogTable> segments;
};

CsvRows read_csv(const fs::path& out) {
  CsvRows rows;
  for (std::size_t k = 1;; ++k) {
    const fs::path p =
        k == 1 ? out : out.parent_path() / (out.stem().string() + "-" + std::to_string(k) + out.extension().string());
    if (!fs::exists(p)) break;
    rows.segments.push_back(datalog::read_log(p));  // throws (test fails) on an invalid log
    const datalog::LogTable& t = rows.segments.back();
    const std::size_t tc = *t.column_index("t");
    for (std::size_t r = 0; r < t.rows(); ++r) {
      rows.sequences.push_back(static_cast<std::uint32_t>(std::lround(t.at(r, tc) / 0.2)) - 2);
    }
  }
  return rows;
}

// The row holds finite_record(sequence)'s values. Tolerance: none; floats
// pass float -> double -> shortest text -> double exactly, and t is
// period x 0.2 s computed the same way (0.2 rounds once, the same both sides).
void expect_row(const datalog::LogTable& t, std::size_t row, std::uint32_t sequence) {
  const app::PeriodRecord<Q> want = finite_record(sequence);
  const auto col = [&](const std::string& name) { return t.at(row, *t.column_index(name)); };
  EXPECT_EQ(col("t"), static_cast<double>(want.period) * 0.2) << "sequence " << sequence;
  for (int k = 0; k < app::PeriodRecord<Q>::kLoadcells; ++k) {
    EXPECT_EQ(static_cast<float>(t.at(row, 1 + static_cast<std::size_t>(k))), want.loadcells_N[k]) << "loadcell " << k;
  }
  EXPECT_EQ(static_cast<float>(col("aux_d")), want.d);
  EXPECT_EQ(std::signbit(col("aux_d")), std::signbit(want.d)) << "-0.0 survives";
  EXPECT_EQ(col("aux_contact"), want.has(app::kRecordContact) ? 1.0 : 0.0);
  EXPECT_EQ(col("aux_mode"), static_cast<double>(static_cast<std::uint8_t>(want.mode)));
  EXPECT_EQ(col("aux_flags"), static_cast<double>(want.flags));
  for (int i = 0; i < Q::kY; ++i) {
    EXPECT_EQ(static_cast<float>(col(std::string("aux_pred_") + Q::kYNames[i])), want.prediction[i]) << "y " << i;
  }
  for (int i = 0; i < Q::kU; ++i) {
    EXPECT_EQ(static_cast<float>(col(std::string("aux_cmd_") + Q::kUNames[i])), want.command[i]) << "u " << i;
  }
  EXPECT_EQ(col("aux_adapt_updates"), static_cast<double>(want.adapt_updates));
  EXPECT_EQ(col("aux_recognized_state"), static_cast<double>(want.recognized_state));
  EXPECT_EQ(static_cast<float>(col("aux_recognized_distance")), want.recognized_distance);
  EXPECT_EQ(col("aux_other_object_state"), want.other_object_state == app::kRecordNoOtherObject
                                               ? -1.0
                                               : static_cast<double>(want.other_object_state));
  EXPECT_EQ(static_cast<float>(col("aux_other_object_distance")), want.other_object_distance);
}

class CliMonitor : public ::testing::Test {
 protected:
  void SetUp() override {
    bus_ = std::make_unique<UsbTestbed>();
    ASSERT_TRUE(bus_->ok()) << bus_->error();
    hand_ = std::make_shared<HandDevice>();
    ASSERT_TRUE(bus_->plug(kHandDevnum, hand_)) << bus_->error();
    dir_ = fs::temp_directory_path() / ("hadynet_monitor_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    out_ = dir_ / "telemetry.csv";
  }
  void TearDown() override { fs::remove_all(dir_); }

  ChildResult monitor(const std::function<void()>& tick) {
    return run_child(*bus_,
                     {HADYNET_CLI_EXECUTABLE, "monitor", "--duration", kDurationS, "--csv", out_.string(), "--quiet"},
                     kChildTimeout, tick);
  }
  // Whether hidapi has an interrupt URB waiting: the child has opened the hand.
  bool reading() const { return bus_->has_pending(kHandDevnum, kHidIn); }
  std::uint64_t reports_taken() const { return bus_->packets(kHandDevnum).of(kHidIn); }
  void publish(std::uint32_t sequence) {
    bus_->locked([&] { hand_->publish(finite_record(sequence)); });
  }

  std::unique_ptr<UsbTestbed> bus_;
  std::shared_ptr<HandDevice> hand_;
  fs::path dir_, out_;
};

// Record k is published once the host has taken the 4 reports of record
// k - 1: nothing may be lost, every record arrives in order.
TEST_F(CliMonitor, RecordsArriveInOrderAndTheCsvHoldsThem) {
  constexpr std::uint32_t kRecords = 20;
  std::uint32_t published = 0;
  const ChildResult r = monitor([&] {
    if (published < kRecords && reading() && reports_taken() == kReportsPerRecord * published) publish(++published);
  });
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  ASSERT_EQ(published, kRecords) << "the child did not take every record: " << r.describe();
  const Summary s = summary(r.err);
  ASSERT_TRUE(s.found) << r.err;
  EXPECT_EQ(s.received, kRecords);
  EXPECT_EQ(s.dropped, 0u);
  EXPECT_EQ(s.malformed, 0u);
  const CsvRows rows = read_csv(out_);
  ASSERT_EQ(rows.segments.size(), 1u) << "no gap, one log";
  EXPECT_EQ(rows.segments[0].metadata.get("format"), "hadynet-log");
  ASSERT_EQ(rows.sequences.size(), kRecords);
  for (std::uint32_t i = 0; i < kRecords; ++i) {
    EXPECT_EQ(rows.sequences[i], i + 1);
    expect_row(rows.segments[0], i, i + 1);
  }
}

// Three records per step while the host reads one report set at a time: the
// device keeps only the newest waiting record (docs/usb.md), so records are
// overwritten. What monitor reports as dropped must equal the gaps between
// the sequence numbers it actually received (its CSV), exactly.
TEST_F(CliMonitor, SlowReaderDropsEqualTheSequenceGapsReceived) {
  constexpr std::uint32_t kRecords = 60;
  std::uint32_t published = 0;
  const ChildResult r = monitor([&] {
    if (published >= kRecords || !reading()) return;
    bus_->locked([&] {
      for (int i = 0; i < 3 && published < kRecords; ++i) hand_->publish(finite_record(++published));
    });
  });
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  const Summary s = summary(r.err);
  ASSERT_TRUE(s.found) << r.err;
  const CsvRows rows = read_csv(out_);
  ASSERT_FALSE(rows.sequences.empty());
  std::uint64_t gaps = 0;
  for (std::size_t i = 1; i < rows.sequences.size(); ++i) {
    ASSERT_GT(rows.sequences[i], rows.sequences[i - 1]) << "in order";
    gaps += rows.sequences[i] - rows.sequences[i - 1] - 1;
  }
  EXPECT_GT(gaps, 0u) << "the queue should have overflowed";
  EXPECT_EQ(s.received, rows.sequences.size());
  EXPECT_EQ(s.dropped, gaps);
  EXPECT_EQ(s.malformed, 0u);
  std::size_t row = 0;
  for (const datalog::LogTable& t : rows.segments) {
    for (std::size_t i = 0; i < t.rows(); ++i) expect_row(t, i, rows.sequences[row++]);
  }
}

// One report cut short on the wire: monitor counts it malformed, loses that
// record (a gap, counted as dropped), keeps the rest, and never logs a
// record assembled from a broken set.
TEST_F(CliMonitor, ShortReportIsCountedAndItsRecordLeftOut) {
  constexpr std::uint32_t kRecords = 6;
  std::uint32_t published = 0;
  bool armed = false;
  const ChildResult r = monitor([&] {
    if (published >= kRecords || !reading() || reports_taken() != kReportsPerRecord * published) return;
    if (published == 2 && !armed) {
      bus_->short_next_in(kHandDevnum, kHidIn, 10);  // part 0 of record 3: 10 of 64 bytes
      armed = true;
    }
    publish(++published);
  });
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  const Summary s = summary(r.err);
  ASSERT_TRUE(s.found) << r.err;
  EXPECT_EQ(s.malformed, 1u);
  EXPECT_EQ(s.received, kRecords - 1);
  EXPECT_EQ(s.dropped, 1u);
  const CsvRows rows = read_csv(out_);
  EXPECT_EQ(rows.sequences, (std::vector<std::uint32_t>{1, 2, 4, 5, 6}));
}

// A STALL handshake on one interrupt URB: hidapi resubmits, the report was
// never consumed, nothing is lost.
TEST_F(CliMonitor, OneStalledTransferLosesNothing) {
  constexpr std::uint32_t kRecords = 4;
  std::uint32_t published = 0;
  bool armed = false;
  const ChildResult r = monitor([&] {
    if (published >= kRecords || !reading() || reports_taken() != kReportsPerRecord * published) return;
    if (published == 1 && !armed) {
      bus_->fail_next_transfer(kHandDevnum, kHidIn, EPIPE);
      armed = true;
    }
    publish(++published);
  });
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  const Summary s = summary(r.err);
  ASSERT_TRUE(s.found) << r.err;
  EXPECT_EQ(s.received, kRecords);
  EXPECT_EQ(s.dropped, 0u);
}

// The hand leaves mid-stream: monitor stops with a non-zero exit and says
// why, long before --duration, and keeps what it had received.
TEST_F(CliMonitor, UnplugEndsWithAnErrorAndKeepsWhatArrived) {
  std::uint32_t published = 0;
  bool unplugged = false;
  const ChildResult r = monitor([&] {
    if (unplugged || !reading() || reports_taken() != kReportsPerRecord * published) return;
    if (published == 3) {
      bus_->unplug(kHandDevnum);
      unplugged = true;
      return;
    }
    publish(++published);
  });
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 1) << r.describe();
  EXPECT_NE(r.err.find("telemetry read failed"), std::string::npos) << r.err;
  const Summary s = summary(r.err);
  ASSERT_TRUE(s.found) << r.err;
  EXPECT_EQ(s.received, 3u);
  EXPECT_EQ(read_csv(out_).sequences, (std::vector<std::uint32_t>{1, 2, 3}));
}

}  // namespace
}  // namespace hadynet::usb::host_testing
