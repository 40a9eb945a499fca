// From logs to HADYNET signals (trainer/log_dataset.h): channel layouts and
// their errors, x_t from y, file expansion and the dataset hash.
// Every comparison is exact: extraction copies doubles and x_t's differences
// are the same single double subtraction as in the reference.
#include "trainer/data_hash.h"
#include "trainer/log_dataset.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "synthetic_logs.h"

namespace hadynet::trainer::testing {
namespace {

namespace fs = std::filesystem;

// A valid table with the given header and `rows` rows of distinct values.
datalog::LogTable table_with(std::vector<std::string> columns, int rows = 3) {
  datalog::LogTable table;
  table.metadata.set("format", "hadynet-log");
  table.metadata.set("format_version", "1");
  table.metadata.set("dt_s", "0.2");
  table.columns = std::move(columns);
  for (int r = 0; r < rows; ++r) {
    std::vector<double> row{0.2 * r};
    for (std::size_t c = 1; c < table.columns.size(); ++c) row.push_back(10.0 * static_cast<double>(c) + r * r);
    table.append_row(row);
  }
  return table;
}

// Runs `f`, expecting std::runtime_error whose message contains every part.
template <class F>
void expect_runtime_error(F&& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    for (const std::string& p : parts) EXPECT_TRUE(contains(e.what(), p)) << e.what() << " lacks " << p;
  }
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
}

TEST(FeatureLayout, XIsEachGroupThenItsDifferencesInHeaderOrder) {
  const datalog::LogTable table =
      table_with({"t", "v0", "v1", "q0", "q1", "q2", "f0", "u0", "u1", "aux_temp"});
  // Delta groups listed in the opposite order of the header: the header decides.
  const FeatureLayout layout = feature_layout(table, "a.csv", {"q", "v"});
  EXPECT_EQ(layout.y_names, (std::vector<std::string>{"v0", "v1", "q0", "q1", "q2", "f0"}));
  EXPECT_EQ(layout.u_names, (std::vector<std::string>{"u0", "u1"}));
  EXPECT_EQ(layout.x_names, (std::vector<std::string>{"v0", "v1", "dv0", "dv1", "q0", "q1", "q2",
                                                      "dq0", "dq1", "dq2", "f0"}));
  EXPECT_EQ(layout.x_source, (std::vector<int>{0, 1, 0, 1, 2, 3, 4, 2, 3, 4, 5}));
  EXPECT_EQ(layout.x_is_delta, (std::vector<bool>{false, false, true, true, false, false, false,
                                                  true, true, true, false}));
  EXPECT_EQ(layout.delta_groups, (std::vector<std::string>{"q", "v"}));

  // Without delta groups x is y.
  const FeatureLayout plain = feature_layout(table, "a.csv", {});
  EXPECT_EQ(plain.x_names, plain.y_names);
}

TEST(FeatureLayout, FromNamesEqualsLayoutOfTheHeader) {
  const FeatureLayout from_log = spring_layout();
  EXPECT_EQ(from_log.x_names,
            (std::vector<std::string>{"q0", "q1", "dq0", "dq1", "v0", "v1"}));
  EXPECT_EQ(feature_layout_from_names(from_log.y_names, from_log.u_names, kSpringDeltaGroups),
            from_log);
  expect_runtime_error([&] { feature_layout_from_names(from_log.y_names, from_log.u_names, {"l"}); },
                       {"'l'"});
  expect_runtime_error([&] { feature_layout_from_names(from_log.y_names, {}, {}); }, {"command"});
}

TEST(FeatureLayout, ErrorsNameTheFile) {
  expect_runtime_error(
      [] { feature_layout(table_with({"t", "q0", "v0"}), "no_u.csv", kSpringDeltaGroups); },
      {"no_u.csv", "command"});
  expect_runtime_error(
      [] { feature_layout(table_with({"t", "q0", "v0", "u0"}), "no_l.csv", {"q", "l"}); },
      {"no_l.csv", "delta group 'l'"});
  // "u" is not an observed group, so it cannot be a delta group either.
  expect_runtime_error(
      [] { feature_layout(table_with({"t", "q0", "v0", "u0"}), "du.csv", {"u"}); },
      {"du.csv", "'u'"});
}

// A model learns one step of one length: every training log must have the
// first one's dt_s (the period the model file then records).
TEST(TrainingLogs, MustShareOneControlPeriod) {
  const datalog::LogTable a = table_with({"t", "q0", "u0"});
  datalog::LogTable b = table_with({"t", "q0", "u0"});
  EXPECT_NO_THROW(check_same_period(a, "a.csv", b, "b.csv"));
  b.metadata.set("dt_s", "0.1");
  expect_runtime_error([&] { check_same_period(a, "a.csv", b, "b.csv"); },
                       {"b.csv", "'dt_s' is 0.1 s", "0.2 s in a.csv"});
}

TEST(LogSequence, ExtractsChannelsByNameAndMetadata) {
  datalog::LogTable table = spring_log(2.0, 12, 5, "cyl/i1", "cylinder");
  // Reorder the header (and the values) to show extraction goes by name.
  datalog::LogTable shuffled = table;
  shuffled.columns = {"t", "v0", "v1", "q0", "q1", "u1", "u0", "aux_energy"};
  const int perm[] = {0, 3, 4, 1, 2, 6, 5, 7};  // shuffled column c = table column perm[c]
  for (std::size_t r = 0; r < table.rows(); ++r)
    for (std::size_t c = 0; c < 8; ++c) shuffled.at(r, c) = table.at(r, static_cast<std::size_t>(perm[c]));

  const FeatureLayout layout = spring_layout();
  const LogSequence seq = log_sequence(shuffled, "dir/run7.csv", layout);
  EXPECT_EQ(seq.file, "dir/run7.csv");
  EXPECT_EQ(seq.state, "cyl/i1");
  EXPECT_EQ(seq.object, "cylinder");
  ASSERT_EQ(seq.steps(), 12);
  ASSERT_EQ(seq.y.rows(), 4);
  ASSERT_EQ(seq.u.rows(), 2);
  for (int t = 0; t < 12; ++t) {
    const auto r = static_cast<std::size_t>(t);
    EXPECT_EQ(seq.y(0, t), table.at(r, 1));  // q0
    EXPECT_EQ(seq.y(1, t), table.at(r, 2));  // q1
    EXPECT_EQ(seq.y(2, t), table.at(r, 3));  // v0
    EXPECT_EQ(seq.y(3, t), table.at(r, 4));  // v1
    EXPECT_EQ(seq.u(0, t), table.at(r, 5));  // u0
    EXPECT_EQ(seq.u(1, t), table.at(r, 6));  // u1
  }

  // Without "state"/"object" metadata: the file stem and "".
  datalog::LogTable bare = table_with({"t", "q0", "q1", "v0", "v1", "u0", "u1"});
  const LogSequence b = log_sequence(bare, "some/dir/run9.csv", layout);
  EXPECT_EQ(b.state, "run9");
  EXPECT_EQ(b.object, "");
}

TEST(LogSequence, MissingModelChannelNamesFileAndChannel) {
  const FeatureLayout layout = spring_layout();
  expect_runtime_error(
      [&] { log_sequence(table_with({"t", "q0", "v0", "v1", "u0", "u1"}), "short.csv", layout); },
      {"short.csv", "'q1'"});
  expect_runtime_error(
      [&] { log_sequence(table_with({"t", "q0", "q1", "v0", "v1", "u0"}), "one_u.csv", layout); },
      {"one_u.csv", "'u1'"});
}

TEST(LogSequence, InitialStateIsYAndItsDifferences) {
  const FeatureLayout layout = spring_layout();  // x = q0 q1 dq0 dq1 v0 v1
  const LogSequence seq = spring_sequence(3.0, 10, 8, "s");
  for (int t = 1; t < seq.steps(); ++t) {
    const Eigen::VectorXd x = initial_state(layout, seq, t);
    ASSERT_EQ(x.size(), 6);
    EXPECT_EQ(x(0), seq.y(0, t));
    EXPECT_EQ(x(1), seq.y(1, t));
    EXPECT_EQ(x(2), seq.y(0, t) - seq.y(0, t - 1));
    EXPECT_EQ(x(3), seq.y(1, t) - seq.y(1, t - 1));
    EXPECT_EQ(x(4), seq.y(2, t));
    EXPECT_EQ(x(5), seq.y(3, t));
  }
  EXPECT_THROW(initial_state(layout, seq, 0), std::out_of_range);  // no y_{-1}
  EXPECT_THROW(initial_state(layout, seq, seq.steps()), std::out_of_range);
}

TEST(LogSequence, ReadSequenceOfAWrittenLogEqualsTheTable) {
  TempDir dir;
  const datalog::LogTable table = spring_log(2.0, 15, 3, "soft");
  const std::string path = dir.write_log("soft.csv", table);
  const FeatureLayout layout = spring_layout();
  const LogSequence read = read_sequence(path, layout);
  const LogSequence direct = log_sequence(table, path, layout);
  EXPECT_EQ(read.file, path);
  EXPECT_EQ(read.state, "soft");
  EXPECT_EQ(read.y, direct.y);  // the log format round-trips doubles exactly
  EXPECT_EQ(read.u, direct.u);

  const std::string missing = (dir.path() / "missing.csv").string();
  try {
    read_sequence(missing, layout);
    ADD_FAILURE() << "no exception";
  } catch (const std::exception& e) {
    EXPECT_TRUE(contains(e.what(), "missing.csv")) << e.what();
  }
}

TEST(ExpandLogPaths, RecursesSortsAndRemovesDuplicates) {
  TempDir dir;
  const datalog::LogTable log = spring_log(1.0, 3, 1, "s");
  const std::string z = dir.write_log("z.csv", log);
  const std::string b = dir.write_log("a/b.csv", log);
  const std::string d = dir.write_log("a/c/d.csv", log);
  write_bytes((dir.path() / "a" / "notes.txt").string(), "not a log\n");
  const std::string other = dir.write_log("other/x.csv", log);

  const std::vector<std::string> got =
      expand_log_paths({dir.path().string(), z, other});  // z and other twice
  EXPECT_EQ(got, (std::vector<std::string>{b, d, other, z}));

  // A file argument is taken as is, whatever its extension.
  const std::string txt = (dir.path() / "a" / "notes.txt").string();
  EXPECT_EQ(expand_log_paths({txt}), std::vector<std::string>{txt});
}

TEST(ExpandLogPaths, MissingPathEmptyFolderAndNoArgumentsAreErrors) {
  TempDir dir;
  const std::string missing = (dir.path() / "nope").string();
  expect_runtime_error([&] { expand_log_paths({missing}); }, {missing});
  fs::create_directories(dir.path() / "empty");
  const std::string empty = (dir.path() / "empty").string();
  expect_runtime_error([&] { expand_log_paths({empty}); }, {empty});
  EXPECT_THROW(expand_log_paths({}), std::runtime_error);
}

TEST(DataHash, StableAndSensitiveToEveryByteAndName) {
  TempDir dir;
  const std::string a = dir.write_log("one/a.csv", spring_log(1.0, 20, 1, "a"));
  const std::string b = dir.write_log("one/b.csv", spring_log(2.0, 20, 2, "b"));
  const std::string h = data_hash({a, b});
  ASSERT_EQ(h.size(), 64u);  // SHA-256
  EXPECT_EQ(h.find_first_not_of("0123456789abcdef"), std::string::npos) << h;
  EXPECT_EQ(data_hash({a, b}), h);  // stable
  EXPECT_NE(data_hash({b, a}), h);  // the given order counts
  EXPECT_NE(data_hash({a}), h);

  // Same names and bytes in another folder: same hash (folders do not count).
  fs::create_directories(dir.path() / "two");
  const std::string a2 = (dir.path() / "two" / "a.csv").string();
  const std::string b2 = (dir.path() / "two" / "b.csv").string();
  fs::copy_file(a, a2);
  fs::copy_file(b, b2);
  EXPECT_EQ(data_hash({a2, b2}), h);

  // A renamed file changes it.
  const std::string renamed = (dir.path() / "two" / "c.csv").string();
  fs::copy_file(b, renamed);
  EXPECT_NE(data_hash({a2, renamed}), h);

  // One changed byte anywhere (first, middle, last) changes it; restoring restores it.
  const std::string original = read_bytes(b2);
  for (const std::size_t pos : {std::size_t{0}, original.size() / 2, original.size() - 1}) {
    std::string changed = original;
    changed[pos] = static_cast<char>(changed[pos] ^ 0x01);
    write_bytes(b2, changed);
    EXPECT_NE(data_hash({a2, b2}), h) << "byte " << pos;
  }
  write_bytes(b2, original);
  EXPECT_EQ(data_hash({a2, b2}), h);

  const std::string missing = (dir.path() / "gone.csv").string();
  expect_runtime_error([&] { data_hash({a, missing}); }, {missing});
}

// A known answer, independent of this code: SHA-256 of "x", a 0 byte and
// "abc" (Python's hashlib.sha256(b"x\x00abc")).
TEST(DataHash, IsSha256OfNameZeroAndBytes) {
  TempDir dir;
  const std::string x = (dir.path() / "x").string();
  write_bytes(x, "abc");
  EXPECT_EQ(data_hash({x}), "7899406e7ba30b3904cd2a37bc0d8d8c77aa96525d34ecf614c69f418e37982b");
}

}  // namespace
}  // namespace hadynet::trainer::testing
