#include "datalog/log_writer.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "datalog/log_reader.h"
#include "test_logs.h"

namespace hadynet::datalog {
namespace {

using test::empty_table;

// Same metadata (order included), same header, every double bit for bit.
void expect_identical(const LogTable& a, const LogTable& b) {
  EXPECT_EQ(a.metadata.entries(), b.metadata.entries());
  EXPECT_EQ(a.columns, b.columns);
  ASSERT_EQ(a.values.size(), b.values.size());
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    ASSERT_EQ(std::bit_cast<std::uint64_t>(a.values[i]), std::bit_cast<std::uint64_t>(b.values[i]))
        << "value " << i << ": " << a.values[i] << " became " << b.values[i];
  }
}

// Rows of the given width with t = row * 0.2 s in column 0 and `fill` elsewhere.
LogTable table_with_rows(std::vector<std::string> columns, std::size_t rows, double fill = 1.0) {
  LogTable table = empty_table(std::move(columns));
  std::vector<double> row(table.columns.size(), fill);
  for (std::size_t r = 0; r < rows; ++r) {
    row[0] = static_cast<double>(r) * 0.2;
    table.append_row(row);
  }
  return table;
}

LogError format_error(const LogTable& table) {
  try {
    format_log(table);
  } catch (const LogError& e) {
    return e;
  }
  ADD_FAILURE() << "format_log accepted the table";
  return LogError("", 0, 0, "", "");
}

// ---- round trip ----

// Values that are hard to print exactly survive format then parse bit for bit.
TEST(RoundTrip, AwkwardValuesBitForBit) {
  using limits = std::numeric_limits<double>;
  const std::vector<double> awkward = {
      0.1, 1e-300, -0.0, 0.0, limits::denorm_min(), -limits::denorm_min(), limits::min(),
      limits::max(), limits::lowest(), 1.0 / 3.0, 2.0 / 3.0, 0.30000000000000004, 1e23,
      9007199254740993.0, -1.5e-7, 4.35, 123456789.123456789, 2.2250738585072009e-308,
      std::nextafter(1.0, 2.0), std::nextafter(0.2, 0.0)};
  LogTable table = empty_table({"t", "l0", "l1", "u0", "aux_x"});
  table.metadata.set("object", "Ø 32 mm cylinder");
  table.metadata.set("note", "  leading and trailing spaces  ");
  table.metadata.set("empty", "");
  for (std::size_t r = 0; r < awkward.size(); ++r) {
    table.append_row({static_cast<double>(r) * 0.2, awkward[r], -awkward[r],
                      awkward[(r + 7) % awkward.size()], awkward[(r + 3) % awkward.size()]});
  }
  expect_identical(parse_log(format_log(table), "mem"), table);
}

// 10 000 random finite bit patterns survive the round trip.
TEST(RoundTrip, RandomBitPatterns) {
  std::mt19937_64 random(20240229);
  LogTable table = empty_table({"t", "f0", "f1", "f2"});
  for (std::size_t r = 0; r < 2500; ++r) {
    std::vector<double> row{static_cast<double>(r) * 0.2};
    while (row.size() < 4) {
      const double value = std::bit_cast<double>(random());
      if (std::isfinite(value)) row.push_back(value);
    }
    table.append_row(row);
  }
  expect_identical(parse_log(format_log(table), "mem"), table);
}

// The text is exactly the documented form: metadata in order ("# key:" for an
// empty value), header, shortest numbers, LF after every line.
TEST(FormatLog, ExactText) {
  LogTable table = empty_table({"t", "l0", "u0"});
  table.metadata.set("source", "");
  table.append_row({0.0, 0.1, -0.0});
  table.append_row({0.2, 1e-300, 12.5});
  EXPECT_EQ(format_log(table),
            "# format: hadynet-log\n"
            "# format_version: 1\n"
            "# dt_s: 0.2\n"
            "# source:\n"
            "t,l0,u0\n"
            "0,0.1,-0\n"
            "0.2,1e-300,12.5\n");
}

// ---- the writer refuses tables the reader would reject ----

// A NaN is reported at the line and field it would have in the file.
TEST(FormatLog, RejectsNonFiniteValue) {
  LogTable table = table_with_rows({"t", "l0", "f0"}, 3);
  table.at(2, 2) = std::numeric_limits<double>::quiet_NaN();
  const LogError e = format_error(table);
  EXPECT_EQ(e.line(), 7u);  // 3 metadata lines, header on 4, rows on 5..7
  EXPECT_EQ(e.column(), 3u);
  EXPECT_EQ(e.column_name(), "f0");
  EXPECT_NE(e.message().find("not written: the value to write is nan"), std::string::npos) << e.what();
}

// Irregular t is refused like in the reader.
TEST(FormatLog, RejectsIrregularTime) {
  LogTable table = table_with_rows({"t", "l0"}, 3);
  table.at(2, 0) = 0.5;
  const LogError e = format_error(table);
  EXPECT_EQ(e.line(), 7u);
  EXPECT_EQ(e.column(), 1u);
  EXPECT_NE(e.message().find("irregular time step"), std::string::npos) << e.what();
}

// A metadata value with a line break would split the line.
TEST(FormatLog, RejectsLineBreakInMetadata) {
  LogTable table = table_with_rows({"t", "l0"}, 1);
  table.metadata.set("object", "ball\n0,1");
  const LogError e = format_error(table);
  EXPECT_EQ(e.line(), 4u);
  EXPECT_NE(e.message().find("value holds a line break"), std::string::npos) << e.what();
}

// Invalid metadata keys are refused.
TEST(FormatLog, RejectsBadMetadataKey) {
  LogTable table = table_with_rows({"t", "l0"}, 1);
  table.metadata.set("Object", "ball");
  const LogError e = format_error(table);
  EXPECT_EQ(e.line(), 4u);
  EXPECT_NE(e.message().find("invalid metadata key 'Object'"), std::string::npos) << e.what();
}

// Metadata must be UTF-8 text.
TEST(FormatLog, RejectsInvalidUtf8) {
  LogTable table = table_with_rows({"t", "l0"}, 1);
  table.metadata.set("object", "\xff");
  const LogError e = format_error(table);
  EXPECT_EQ(e.line(), 4u);
  EXPECT_NE(e.message().find("invalid UTF-8"), std::string::npos) << e.what();
}

// Required metadata missing: the same error as the reader's.
TEST(FormatLog, RejectsMissingRequiredMetadata) {
  LogTable table;
  table.metadata.set("format", "hadynet-log");
  table.metadata.set("dt_s", "0.2");
  table.columns = {"t", "l0"};
  table.append_row({0.0, 1.0});
  const LogError e = format_error(table);
  EXPECT_EQ(e.line(), 0u);
  EXPECT_NE(e.message().find("format_version"), std::string::npos) << e.what();
}

// A column name with a comma would change the header.
TEST(FormatLog, RejectsBadColumnName) {
  const LogError e = format_error(table_with_rows({"t", "l0", "aux_a,b"}, 1));
  EXPECT_EQ(e.line(), 4u);
  EXPECT_EQ(e.column(), 3u);
  EXPECT_NE(e.message().find("name fits no rule"), std::string::npos) << e.what();
}

// A table without rows, and one whose values do not fill whole rows.
TEST(FormatLog, RejectsNoRowsAndRaggedValues) {
  EXPECT_NE(format_error(empty_table({"t", "l0"})).message().find("no data rows"),
            std::string::npos);
  LogTable ragged = table_with_rows({"t", "l0"}, 2);
  ragged.values.push_back(1.0);
  EXPECT_NE(format_error(ragged).message().find("expected a multiple of the 2 columns"),
            std::string::npos);
}

// ---- write_log ----

class WriteLog : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "datalog_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    folder_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::vector<std::string> folder_entries() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(folder_)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  static std::string file_bytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
  }

  std::filesystem::path folder_;
};

// The final file is complete, reads back identical, and no temporary file
// is left in the folder.
TEST_F(WriteLog, WritesCompleteFileAndLeavesNoTemporary) {
  const LogTable table = table_with_rows({"t", "l0", "f0", "u0"}, 500, 0.1);
  const auto path = folder_ / "run.csv";
  write_log(path, table);
  EXPECT_EQ(folder_entries(), std::vector<std::string>{"run.csv"});
  EXPECT_EQ(file_bytes(path), format_log(table));
  expect_identical(read_log(path), table);
}

// Writing over an existing log replaces it whole (a longer old file leaves no tail).
TEST_F(WriteLog, ReplacesExistingFile) {
  const auto path = folder_ / "run.csv";
  write_log(path, table_with_rows({"t", "l0"}, 1000));
  const LogTable small = table_with_rows({"t", "l0"}, 2, 7.0);
  write_log(path, small);
  EXPECT_EQ(folder_entries(), std::vector<std::string>{"run.csv"});
  expect_identical(read_log(path), small);
}

// A table the format rejects changes nothing on disk.
TEST_F(WriteLog, InvalidTableLeavesOldFileUntouched) {
  const auto path = folder_ / "run.csv";
  write_log(path, table_with_rows({"t", "l0"}, 3));
  const std::string before = file_bytes(path);
  LogTable bad = table_with_rows({"t", "l0"}, 3);
  bad.at(1, 1) = std::numeric_limits<double>::infinity();
  try {
    write_log(path, bad);
    FAIL() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_EQ(e.line(), 6u);
    EXPECT_EQ(e.column(), 2u);
  }
  EXPECT_EQ(file_bytes(path), before);
  EXPECT_EQ(folder_entries(), std::vector<std::string>{"run.csv"});
}

// A folder that does not exist is a clear LogError and creates nothing.
TEST_F(WriteLog, MissingFolderIsClearError) {
  const auto path = folder_ / "missing" / "run.csv";
  try {
    write_log(path, table_with_rows({"t", "l0"}, 1));
    FAIL() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_NE(e.message().find("No such file or directory"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(folder_entries().empty());
}

// A writer killed (SIGKILL) at various moments never leaves a partial file
// under the final name: it holds either the previous complete log or the new
// complete one. Only hidden temporaries may remain.
TEST_F(WriteLog, KilledWriterNeverLeavesPartialFile) {
  const auto path = folder_ / "run.csv";
  const std::size_t rows = 20000;
  std::vector<std::string> columns = {"t"};
  for (int i = 0; i < 27; ++i) columns.push_back(std::string("y").append(std::to_string(i)));
  const LogTable table = table_with_rows(columns, rows, 1.0 / 3.0);

  for (int delay_ms : {0, 1, 2, 5, 10, 20}) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      for (;;) {
        try {
          write_log(path, table);
        } catch (...) {
          ::_exit(1);
        }
      }
    }
    // Kill mid-write: after the first complete file exists (first round) or
    // while overwriting it (later rounds).
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!std::filesystem::exists(path) && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "writer failed before it was killed";

    const LogTable back = read_log(path);  // throws on a partial file
    EXPECT_EQ(back.rows(), rows) << "after kill at +" << delay_ms << " ms";
  }
  for (const std::string& name : folder_entries()) {
    if (name != "run.csv") {
      EXPECT_EQ(name.rfind(".run.csv.tmp-", 0), 0u) << name;
    }
  }
}

}  // namespace
}  // namespace hadynet::datalog
