// The telemetry stream as HADYNET logs (tools/usb/telemetry_log.h): the
// columns come from the generated model's channel names, a record's fields
// land in its row exactly (float -> double is exact, the writer prints the
// shortest round-tripping text, so the log reads back bit for bit: tolerance
// zero), a gap in the period index or a non-finite record starts a new log,
// and every log passes the strict reader.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "datalog/log_reader.h"
#include "datalog/log_writer.h"
#include "hadynet_model_q15.h"
#include "tools/usb/telemetry_log.h"

namespace hadynet::tools::usb {
namespace {

using Q = model_q15::Model;
using Log = TelemetryLog<Q>;
using Layout = app::ChannelLayout<Q>;

app::PeriodRecord<Q> record(std::uint32_t period) {
  app::PeriodRecord<Q> r;
  r.sequence = period + 1;
  r.period = period;
  r.mode = firmware::Mode::kControl;
  r.flags = app::kRecordStepped | app::kRecordDistanceValid | app::kRecordCommandValid |
            (period % 3 == 0 ? app::kRecordContact : 0);
  for (int k = 0; k < Layout::kLoadcells; ++k) r.loadcells_N[k] = 0.1f * static_cast<float>(k) + static_cast<float>(period);
  r.d = 1.0f / static_cast<float>(period + 3);
  for (int i = 0; i < Q::kY; ++i) r.prediction[i] = -0.3f * static_cast<float>(i) + 1e-7f * static_cast<float>(period);
  for (int i = 0; i < Q::kU; ++i) r.command[i] = 0.01f * static_cast<float>(i + period);
  return r;
}

TEST(TelemetryLog, ColumnsAreTheModelsNames) {
  const auto& c = Log::columns();
  ASSERT_EQ(c.size(), 1u + Layout::kLoadcells + 4 + Q::kY + Q::kU + 5);
  EXPECT_EQ(c[0], "t");
  EXPECT_EQ(c[1], Q::kYNames[Layout::kLoadcellY[0]]);
  EXPECT_EQ(c[1 + Layout::kLoadcells], "aux_d");
  EXPECT_EQ(c[1 + Layout::kLoadcells + 4], std::string("aux_pred_") + Q::kYNames[0]);
  EXPECT_EQ(c[Layout::kLoadcells + 4 + Q::kY + Q::kU], std::string("aux_cmd_") + Q::kUNames[Q::kU - 1]);
  EXPECT_EQ(c[c.size() - 5], "aux_adapt_updates");
  EXPECT_EQ(c.back(), "aux_other_object_distance");
}

TEST(TelemetryLog, RecordsRoundTripBitForBitThroughTheWriterAndReader) {
  Log log("test");
  for (std::uint32_t p = 10; p < 20; ++p) ASSERT_TRUE(log.add(record(p)));
  ASSERT_EQ(log.segments().size(), 1u);
  const datalog::LogTable back = datalog::parse_log(datalog::format_log(log.segments()[0]), "telemetry.csv");
  ASSERT_EQ(back.rows(), 10u);
  for (std::size_t row = 0; row < back.rows(); ++row) {
    const auto r = record(static_cast<std::uint32_t>(10 + row));
    EXPECT_EQ(back.at(row, 0), static_cast<double>(r.period) * 0.2);
    for (int k = 0; k < Layout::kLoadcells; ++k) EXPECT_EQ(back.at(row, 1 + k), static_cast<double>(r.loadcells_N[k]));
    const std::size_t aux = 1 + Layout::kLoadcells;
    EXPECT_EQ(back.at(row, aux), static_cast<double>(r.d));
    EXPECT_EQ(back.at(row, aux + 1), r.has(app::kRecordContact) ? 1.0 : 0.0);
    EXPECT_EQ(back.at(row, aux + 2), 2.0);  // control
    EXPECT_EQ(back.at(row, aux + 3), static_cast<double>(r.flags));
    for (int i = 0; i < Q::kY; ++i) EXPECT_EQ(back.at(row, aux + 4 + i), static_cast<double>(r.prediction[i]));
    for (int i = 0; i < Q::kU; ++i) EXPECT_EQ(back.at(row, aux + 4 + Q::kY + i), static_cast<double>(r.command[i]));
  }
}

TEST(TelemetryLog, AGapOrANonFiniteRecordStartsANewLog) {
  Log log("test");
  for (std::uint32_t p = 0; p < 5; ++p) ASSERT_TRUE(log.add(record(p)));
  for (std::uint32_t p = 7; p < 9; ++p) ASSERT_TRUE(log.add(record(p)));  // periods 5, 6 dropped
  auto bad = record(9);
  bad.d = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(log.add(bad));
  ASSERT_TRUE(log.add(record(10)));  // contiguous with 9, but 9 is not in any log
  ASSERT_EQ(log.segments().size(), 3u);
  EXPECT_EQ(log.segments()[0].rows(), 5u);
  EXPECT_EQ(log.segments()[1].rows(), 2u);
  EXPECT_EQ(log.segments()[2].rows(), 1u);
  EXPECT_EQ(log.skipped_records(), 1u);
  for (const auto& seg : log.segments()) {
    EXPECT_NO_THROW(datalog::parse_log(datalog::format_log(seg), "segment.csv")) << "every segment is a valid log";
  }
}

}  // namespace
}  // namespace hadynet::tools::usb
