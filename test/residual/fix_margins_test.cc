// The --fix margins have one source (fix_margins.h): docs/residual.md's
// "Test margins" table must be margins_table(), line for line. On a mismatch
// the test prints the table to paste into the docs.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "test/residual/fix_margins.h"

namespace hadynet::test {
namespace {

// The lines of the Markdown table in `path` whose first line is `header`
// (up to the first line that is not a table row); empty if there is none.
std::vector<std::string> table_in(const std::string& path, const std::string& header) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  std::string line;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!inside && line != header) continue;
    if (inside && line.rfind("|", 0) != 0) break;
    inside = true;
    lines.push_back(line);
  }
  return lines;
}

TEST(FixMargins, DocsTableIsThisTable) {
  const std::vector<std::string> want = fix_margins::margins_table();
  const std::string docs = std::string(HADYNET_SOURCE_DIR) + "/docs/residual.md";
  ASSERT_TRUE(std::ifstream(docs).good()) << docs;
  const std::vector<std::string> got = table_in(docs, want.front());
  std::string table;
  for (const auto& line : want) table += line + "\n";
  ASSERT_FALSE(got.empty()) << docs << " has no table headed\n" << want.front()
                            << "\nThe table (test/residual/fix_margins.h):\n" << table;
  EXPECT_EQ(got, want) << docs << ": the margins table differs from test/residual/fix_margins.h; it is:\n" << table;
}

// The bounds are consistent with what they were set on: every measured value
// passes its own bound (a bound moved past its measurement is a typo).
TEST(FixMargins, EveryMeasuredValuePassesItsBound) {
  using namespace fix_margins;
  for (const Below& b : {kSensorDelay.winner_vs_before, kSensorDelay.winner_vs_control, kSensorDelay.aligned_vs_before,
                         kSensorDelay.aligned_median, kFriction.winner_vs_before, kFriction.winner_vs_control,
                         kFriction.family_vs_before, kCrosstalk.winner_vs_before, kCrosstalk.winner_vs_control,
                         kCrosstalk.further_vs_before, kCrosstalk.further_vs_control,
                         kDrift.winner_vs_before, kDrift.winner_vs_control, kDrift.family_vs_before,
                         kDrift.each_vs_control, kDrift.group_vs_control, kDriftProbe.group_vs_before,
                         kDriftProbe.group_vs_control, kDriftProbe.decision_p,
                         kDefaultDriftLongLogs.winner_vs_before, kDefaultDriftLongLogs.decision_p,
                         kSaturation.winner_vs_before, kSaturation.winner_vs_control, kSaturation.rail_error_N,
                         kAux.winner_vs_before, kAux.winner_vs_control, kSpringDelay.winner_vs_before,
                         kSpringDelay.winner_vs_control})
    EXPECT_LT(b.measured, b.limit);
  for (const Between& b : {kCrosstalk.gain, kDrift.rate_vs_plant, kDriftProbe.rate_vs_plant,
                           kDefaultDriftLongLogs.rate_vs_plant}) {
    EXPECT_GT(b.measured, b.lo);
    EXPECT_LT(b.measured, b.hi);
  }
  EXPECT_GT(kCrosstalk.target_ljung_box_p.measured, kCrosstalk.target_ljung_box_p.limit);
}

}  // namespace
}  // namespace hadynet::test
