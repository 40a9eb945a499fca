#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "datalog/log_reader.h"
#include "test_logs.h"

namespace hadynet::datalog {
namespace {

std::vector<std::size_t> range(std::size_t first, std::size_t count) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < count; ++i) out.push_back(first + i);
  return out;
}

// The hand's header gives y = (l 8, f 8, fc 9, th 2) = 27 observed channels
// in header order and u = 8 commands (docs/architecture.md §2).
TEST(ChannelLayout, MusashiHand) {
  std::string row = "0";  // t plus 35 channels
  for (int i = 0; i < 35; ++i) row += ",0";
  const LogTable table =
      parse_log(test::kRequiredMetadata + test::hand_header() + "\n" + row + "\n", "hand.csv");
  ASSERT_EQ(table.columns.size(), 36u);
  const ChannelLayout layout = channel_layout(table, "hand.csv");
  EXPECT_EQ(layout.time_column, 0u);
  ASSERT_EQ(layout.observed.size(), 4u);
  EXPECT_EQ(layout.observed[0].prefix, "l");
  EXPECT_EQ(layout.observed[0].columns, range(1, 8));
  EXPECT_EQ(layout.observed[1].prefix, "f");
  EXPECT_EQ(layout.observed[1].columns, range(9, 8));
  EXPECT_EQ(layout.observed[2].prefix, "fc");
  EXPECT_EQ(layout.observed[2].columns, range(17, 9));
  EXPECT_EQ(layout.observed[3].prefix, "th");
  EXPECT_EQ(layout.observed[3].columns, range(26, 2));
  ASSERT_TRUE(layout.command.has_value());
  EXPECT_EQ(layout.command->prefix, "u");
  EXPECT_EQ(layout.command->columns, range(28, 8));
  EXPECT_FALSE(layout.aux.has_value());
}

// Another robot: groups come from the names, not from the hand's sizes.
TEST(ChannelLayout, OtherRobot) {
  const LogTable table = test::empty_table({"t", "q0", "q1", "tau0", "u0", "aux_temp"});
  const ChannelLayout layout = channel_layout(table, "arm.csv");
  EXPECT_EQ(layout.time_column, 0u);
  ASSERT_EQ(layout.observed.size(), 2u);
  EXPECT_EQ(layout.observed[0].prefix, "q");
  EXPECT_EQ(layout.observed[0].columns, (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(layout.observed[1].prefix, "tau");
  EXPECT_EQ(layout.observed[1].columns, (std::vector<std::size_t>{3}));
  ASSERT_TRUE(layout.command.has_value());
  EXPECT_EQ(layout.command->columns, (std::vector<std::size_t>{4}));
  ASSERT_TRUE(layout.aux.has_value());
  EXPECT_EQ(layout.aux->prefix, "aux_");
  EXPECT_EQ(layout.aux->columns, (std::vector<std::size_t>{5}));
}

// Interleaved groups, 't' in the middle, several aux channels, no command
// group: each group keeps its own channel order.
TEST(ChannelLayout, InterleavedGroupsWithoutCommand) {
  const LogTable table =
      test::empty_table({"q0", "dq0", "aux_motor_temp_C", "t", "q1", "dq1", "aux_Vbus"});
  const ChannelLayout layout = channel_layout(table, "x.csv");
  EXPECT_EQ(layout.time_column, 3u);
  ASSERT_EQ(layout.observed.size(), 2u);
  EXPECT_EQ(layout.observed[0].columns, (std::vector<std::size_t>{0, 4}));
  EXPECT_EQ(layout.observed[1].prefix, "dq");
  EXPECT_EQ(layout.observed[1].columns, (std::vector<std::size_t>{1, 5}));
  EXPECT_FALSE(layout.command.has_value());
  EXPECT_EQ(layout.aux->columns, (std::vector<std::size_t>{2, 6}));
}

// On an in-memory table the error points at the header line its file form
// would have: metadata entries + 1 (here 3 + 1 extra key + 1 = 5).
TEST(ChannelLayout, ErrorLineOfInMemoryTable) {
  LogTable table = test::empty_table({"t", "l0", "l2"});
  table.metadata.set("object", "ball");
  try {
    channel_layout(table, "mem");
    FAIL() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_EQ(e.line(), 5u);
    EXPECT_EQ(e.column(), 3u);
    EXPECT_EQ(e.column_name(), "l2");
    EXPECT_NE(e.message().find("expected 'l1'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hadynet::datalog
