// The held-out logs a trained model stores (trainer/held_out_logs.h): each
// is the tail of its training log that no training window touches, exactly
// (values bit for bit, metadata kept), and contains_rows() tells a log that
// holds those rows from one that does not. No tolerances: rows and values
// are compared exactly.
#include "trainer/held_out_logs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "datalog/log_reader.h"
#include "synthetic_logs.h"

namespace hadynet::trainer::testing {
namespace {

constexpr int kSteps = 4;

TEST(HeldOutLogs, AreTheTailsNoTrainingWindowTouches) {
  TempDir dir;
  const std::vector<datalog::LogTable> tables = {spring_log(kSoftStiffness, 40, 1, "soft"),
                                                 spring_log(kStiffStiffness, 5, 2, "stiff"),  // no window
                                                 spring_log(kStiffStiffness, 31, 3, "stiff")};
  std::vector<std::string> paths;
  std::vector<LogSequence> seqs;
  const FeatureLayout layout = spring_layout();
  for (std::size_t k = 0; k < tables.size(); ++k) {
    paths.push_back(dir.write_log("log" + std::to_string(k) + ".csv", tables[k]));
    seqs.push_back(log_sequence(tables[k], paths.back(), layout));
  }
  const WindowDataset data(seqs, {0, 1, 1}, layout, fit_normalization(seqs, layout), kSteps);
  const WindowDataset::Split split = data.split_tail(0.2);
  const std::vector<StoredLog> logs = held_out_logs(paths, data, split);
  ASSERT_EQ(logs.size(), 2u) << "one per log with held-out windows";

  for (const auto& [log_index, stored] : {std::pair{0, logs[0]}, std::pair{2, logs[1]}}) {
    const datalog::LogTable& full = tables[static_cast<std::size_t>(log_index)];
    // The last row any training window of this log reads (rows start-1 .. start+N).
    int last_training_row = -1, first_held_start = 1 << 30;
    for (const int id : split.train)
      if (data.window(id).sequence == log_index)
        last_training_row = std::max(last_training_row, data.window(id).start + kSteps);
    for (const int id : split.held_out)
      if (data.window(id).sequence == log_index)
        first_held_start = std::min(first_held_start, data.window(id).start);
    const std::size_t first_row = static_cast<std::size_t>(first_held_start - 1);
    EXPECT_LT(last_training_row, static_cast<int>(first_row)) << "no training row in the stored log";
    EXPECT_EQ(stored.name, paths[static_cast<std::size_t>(log_index)] + " rows " + std::to_string(first_row) + ".." +
                               std::to_string(full.rows() - 1));

    const datalog::LogTable part = datalog::parse_log(stored.text, stored.name);
    EXPECT_EQ(part.columns, full.columns);
    EXPECT_EQ(part.metadata.entries(), full.metadata.entries());
    ASSERT_EQ(part.rows(), full.rows() - first_row);
    EXPECT_TRUE(std::equal(part.values.begin(), part.values.end(),
                           full.values.begin() + static_cast<std::ptrdiff_t>(first_row * full.columns.size())));
    EXPECT_TRUE(contains_rows(full, part));
    EXPECT_FALSE(contains_rows(tables[log_index == 0 ? 2 : 0], part)) << "another log does not hold them";
  }
  EXPECT_TRUE(held_out_logs(paths, data, data.split_tail(0.0)).empty()) << "nothing held out, nothing stored";
}

TEST(HeldOutLogs, ContainsRowsNeedsEveryRowInOrderAndEveryColumn) {
  const datalog::LogTable log = spring_log(kSoftStiffness, 20, 5, "soft");
  datalog::LogTable part = log;
  const std::size_t width = log.columns.size();
  part.values.assign(log.values.begin() + static_cast<std::ptrdiff_t>(6 * width),
                     log.values.begin() + static_cast<std::ptrdiff_t>(12 * width));
  EXPECT_TRUE(contains_rows(log, part));
  datalog::LogTable changed = part;
  changed.at(3, width - 1) += 1e-12;  // one value of one row
  EXPECT_FALSE(contains_rows(log, changed));
  datalog::LogTable swapped = part;  // two rows in the other order
  std::swap_ranges(swapped.values.begin(), swapped.values.begin() + static_cast<std::ptrdiff_t>(width),
                   swapped.values.begin() + static_cast<std::ptrdiff_t>(width));
  EXPECT_FALSE(contains_rows(log, swapped));
  datalog::LogTable renamed = part;
  renamed.columns.back() = "other";
  EXPECT_FALSE(contains_rows(log, renamed));
  EXPECT_FALSE(contains_rows(part, log)) << "a longer log is not inside a shorter one";
}

}  // namespace
}  // namespace hadynet::trainer::testing
