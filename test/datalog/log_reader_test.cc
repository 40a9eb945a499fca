#include "datalog/log_reader.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <string>

#include "test_logs.h"

namespace hadynet::datalog {
namespace {

using test::kRequiredMetadata;

// ---- valid input ----

// Metadata (required, conventional and unknown keys) is kept in file order;
// the header and every value arrive as written.
TEST(ParseLog, ReadsMetadataHeaderAndValues) {
  const std::string text = kRequiredMetadata +
                           "# state: none-init0\n"
                           "# units: t=s l=mm f=N u=mm\n"
                           "# operator_note: Ø 32 mm cylinder\n"
                           "# source:\n"
                           "t,l0,f0,u0\n"
                           "0,1.5,-2,0.001\n"
                           "0.2,1e-3,-0,3\n";
  const LogTable table = parse_log(text, "a.csv");
  ASSERT_EQ(table.metadata.entries().size(), 7u);
  EXPECT_EQ(table.metadata.entries()[3].first, "state");
  EXPECT_EQ(table.metadata.get("units"), "t=s l=mm f=N u=mm");
  EXPECT_EQ(table.metadata.get("operator_note"), "Ø 32 mm cylinder");
  EXPECT_EQ(table.metadata.get("source"), "");
  EXPECT_EQ(table.columns, (std::vector<std::string>{"t", "l0", "f0", "u0"}));
  ASSERT_EQ(table.rows(), 2u);
  EXPECT_EQ(table.at(0, 1), 1.5);
  EXPECT_EQ(table.at(0, 3), 0.001);
  EXPECT_EQ(table.at(1, 0), 0.2);
  EXPECT_EQ(table.at(1, 1), 1e-3);
  EXPECT_TRUE(std::signbit(table.at(1, 2)));  // "-0" stays negative zero
}

// 't' need not be the first column; groups may interleave.
TEST(ParseLog, AcceptsTimeAnywhereAndInterleavedGroups) {
  const LogTable table = parse_log(kRequiredMetadata + "q0,dq0,t,q1,dq1\n1,2,5,3,4\n", "a.csv");
  EXPECT_EQ(table.at(0, 2), 5.0);
}

// Jitter in t below the tolerance (1e-6 + 1e-4 * dt_s = 2.1e-5 s at 0.2 s) passes.
TEST(ParseLog, AcceptsTimeJitterWithinTolerance) {
  const LogTable table =
      parse_log(kRequiredMetadata + "t,l0\n0,1\n0.20002,1\n0.40001,1\n", "a.csv");
  EXPECT_EQ(table.rows(), 3u);
}

// Floating-point sums of dt_s (0.6000000000000001 after 0.4) are regular.
TEST(ParseLog, AcceptsAccumulatedTime) {
  std::string text = kRequiredMetadata + "t,l0\n";
  double t = 0.0;
  for (int i = 0; i < 1000; ++i, t += 0.2) {
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, t).ptr;
    text += std::string(buffer, end) + ",0\n";
  }
  EXPECT_EQ(parse_log(text, "a.csv").rows(), 1000u);
}

// ---- read_log ----

// A missing file is a LogError naming the file and the system's reason.
TEST(ReadLog, MissingFileIsClearError) {
  const std::filesystem::path path = "/nonexistent-hadynet-folder/run.csv";
  try {
    read_log(path);
    FAIL() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_EQ(e.line(), 0u);
    EXPECT_EQ(e.column(), 0u);
    EXPECT_NE(e.message().find("cannot read log file: No such file or directory"), std::string::npos)
        << e.what();
  }
}

// A folder is not a log.
TEST(ReadLog, FolderIsClearError) {
  try {
    read_log(std::filesystem::temp_directory_path());
    FAIL() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_NE(e.message().find("Is a directory"), std::string::npos) << e.what();
  }
}

// ---- bad input: one case per rule, each with its exact location ----

struct BadLog {
  const char* name;         // test name suffix
  std::string text;         // the whole file
  std::size_t line;         // expected LogError::line()
  std::size_t column;       // expected LogError::column()
  const char* column_name;  // expected LogError::column_name()
  const char* phrase;       // must occur in LogError::message()
};

void PrintTo(const BadLog& c, std::ostream* os) { *os << c.name; }

class ParseLogRejects : public ::testing::TestWithParam<BadLog> {};

// Each case: parse_log throws a LogError at exactly (line, column, column
// name) whose message contains the phrase.
TEST_P(ParseLogRejects, WithExactLocationAndMessage) {
  const BadLog& c = GetParam();
  try {
    const LogTable table = parse_log(c.text, "runs/a.csv");
    FAIL() << "accepted, rows: " << table.rows();
  } catch (const LogError& e) {
    EXPECT_EQ(e.file(), "runs/a.csv");
    EXPECT_EQ(e.line(), c.line) << e.what();
    EXPECT_EQ(e.column(), c.column) << e.what();
    EXPECT_EQ(e.column_name(), c.column_name) << e.what();
    EXPECT_NE(e.message().find(c.phrase), std::string::npos)
        << "message: " << e.message() << "\nexpected phrase: " << c.phrase;
  }
}

std::string bad_log_name(const ::testing::TestParamInfo<BadLog>& case_info) {
  return case_info.param.name;
}

const std::string M = kRequiredMetadata;  // lines 1-3; header is line 4

// clang-format off
INSTANTIATE_TEST_SUITE_P(File, ParseLogRejects, ::testing::Values(
    // Nothing at all.
    BadLog{"EmptyFile", "", 0, 0, "", "empty file"},
    // Metadata, then the file ends.
    BadLog{"MetadataWithoutHeader", M, 0, 0, "", "no header row"},
    // Header, then the file ends.
    BadLog{"HeaderWithoutDataRows", M + "t,l0\n", 0, 0, "", "no data rows"},
    // A writer killed mid-line: the last line has no '\n'.
    BadLog{"TruncatedLastLine", M + "t,l0\n0,1\n0.2,1", 6, 0, "",
           "truncated last line (no newline at end of file)"},
    // Windows line ends.
    BadLog{"CrLf", M + "t,l0\r\n0,1\r\n", 4, 0, "", "carriage return"},
    // A byte order mark before the first line.
    BadLog{"ByteOrderMark", "\xEF\xBB\xBF" + M + "t,l0\n0,1\n", 1, 0, "", "byte order mark"},
    // Latin-1 text in a metadata value (byte 10 of line 4).
    BadLog{"InvalidUtf8", M + "# object: \xD8 32\nt,l0\n0,1\n", 4, 0, "",
           "invalid UTF-8 at byte 11 of the line"}),
    bad_log_name);

INSTANTIATE_TEST_SUITE_P(Metadata, ParseLogRejects, ::testing::Values(
    // No '# format:' line: not a HADYNET log.
    BadLog{"MissingFormat", "# format_version: 1\n# dt_s: 0.2\nt,l0\n0,1\n", 0, 0, "",
           "missing required metadata line '# format: ...'"},
    BadLog{"WrongFormat", "# format: csv\n# format_version: 1\n# dt_s: 0.2\nt,l0\n0,1\n", 1, 0, "",
           "metadata 'format': expected 'hadynet-log', got 'csv'"},
    BadLog{"MissingVersion", "# format: hadynet-log\n# dt_s: 0.2\nt,l0\n0,1\n", 0, 0, "",
           "missing required metadata line '# format_version: ...'"},
    // A newer version: the message names the supported one.
    BadLog{"UnsupportedVersion", "# format: hadynet-log\n# format_version: 2\n# dt_s: 0.2\nt,l0\n0,1\n",
           2, 0, "", "unsupported format_version '2'; the supported format_version is 1"},
    BadLog{"VersionWithLeadingZero", "# format: hadynet-log\n# format_version: 01\n# dt_s: 0.2\nt,l0\n0,1\n",
           2, 0, "", "unsupported format_version '01'"},
    BadLog{"MissingDt", "# format: hadynet-log\n# format_version: 1\nt,l0\n0,1\n", 0, 0, "",
           "missing required metadata line '# dt_s: ...'"},
    BadLog{"NegativeDt", "# format: hadynet-log\n# format_version: 1\n# dt_s: -0.2\nt,l0\n0,1\n",
           3, 0, "", "metadata 'dt_s': expected a number of seconds from 1e-09 to 1e+06, got '-0.2'"},
    BadLog{"NanDt", "# format: hadynet-log\n# format_version: 1\n# dt_s: nan\nt,l0\n0,1\n",
           3, 0, "", "expected a number of seconds from 1e-09 to 1e+06, got 'nan'"},
    BadLog{"DtWithUnit", "# format: hadynet-log\n# format_version: 1\n# dt_s: 0.2 s\nt,l0\n0,1\n",
           3, 0, "", "got '0.2 s'"},
    BadLog{"DuplicateKey", M + "# seed: 1\n# seed: 2\nt,l0\n0,1\n", 5, 0, "",
           "duplicate metadata key 'seed' (first on line 4)"},
    BadLog{"UppercaseKey", M + "# Seed: 1\nt,l0\n0,1\n", 4, 0, "", "invalid metadata key 'Seed'"},
    BadLog{"NoSpaceAfterHash", M + "#seed: 1\nt,l0\n0,1\n", 4, 0, "",
           "malformed metadata line: expected '# key: value', got '#seed: 1'"},
    BadLog{"NoColon", M + "# seed 1\nt,l0\n0,1\n", 4, 0, "", "malformed metadata line"},
    // A '#' line between data rows.
    BadLog{"MetadataAfterHeader", M + "t,l0\n0,1\n# seed: 1\n0.4,1\n", 6, 0, "",
           "metadata line after the header"}),
    bad_log_name);

INSTANTIATE_TEST_SUITE_P(Header, ParseLogRejects, ::testing::Values(
    BadLog{"MissingTime", M + "l0,f0\n1,2\n", 4, 0, "", "missing time column 't'"},
    BadLog{"DuplicateColumn", M + "t,l0,l0\n0,1,2\n", 4, 3, "l0",
           "duplicate column name (first at column 2)"},
    BadLog{"DuplicateTime", M + "t,l0,t\n0,1,2\n", 4, 3, "t", "duplicate column name"},
    BadLog{"NameFitsNoRule", M + "t,l0,Force\n0,1,2\n", 4, 3, "Force", "name fits no rule"},
    BadLog{"NameWithoutIndex", M + "t,l\n0,1\n", 4, 2, "l", "name fits no rule"},
    BadLog{"IndexWithLeadingZero", M + "t,l01\n0,1\n", 4, 2, "l01", "name fits no rule"},
    BadLog{"AuxWithoutName", M + "t,l0,aux_\n0,1,2\n", 4, 3, "aux_", "name fits no rule"},
    BadLog{"SpaceInName", M + "t, l0\n0,1\n", 4, 2, " l0", "name fits no rule"},
    BadLog{"EmptyColumnName", M + "t,,l0\n0,1,2\n", 4, 2, "", "empty column name"},
    BadLog{"EmptyHeader", M + "\n0,1\n", 4, 0, "", "empty header row"},
    // A gap in a group: l0, l2.
    BadLog{"GroupGap", M + "t,l0,l2\n0,1,2\n", 4, 3, "l2",
           "channel index out of order in group 'l': expected 'l1'"},
    BadLog{"GroupNotFromZero", M + "t,f1\n0,1\n", 4, 2, "f1", "expected 'f0'"},
    BadLog{"GroupOutOfOrder", M + "t,th1,th0\n0,1,2\n", 4, 2, "th1", "expected 'th0'"},
    // Commands and aux only: nothing to model.
    BadLog{"NoObservedGroup", M + "t,u0,aux_temp\n0,1,2\n", 4, 0, "", "no observed channel group"}),
    bad_log_name);

INSTANTIATE_TEST_SUITE_P(Data, ParseLogRejects, ::testing::Values(
    BadLog{"TooFewFields", M + "t,l0,f0\n0,1,2\n0.2,1\n", 6, 0, "",
           "expected 3 fields (one per header column), got 2"},
    BadLog{"TooManyFields", M + "t,l0,f0\n0,1,2,3\n", 5, 0, "", "expected 3 fields (one per header column), got 4"},
    BadLog{"TrailingComma", M + "t,l0\n0,1,\n", 5, 0, "", "expected 2 fields (one per header column), got 3"},
    BadLog{"Nan", M + "t,l0,f0\n0,nan,2\n", 5, 2, "l0", "expected a finite number, got 'nan'"},
    BadLog{"Inf", M + "t,l0,f0\n0,1,inf\n", 5, 3, "f0", "expected a finite number, got 'inf'"},
    BadLog{"NegativeInf", M + "t,l0,f0\n0,1,-inf\n", 5, 3, "f0", "got '-inf'"},
    BadLog{"Overflow", M + "t,l0\n0,1e999\n", 5, 2, "l0", "got '1e999'"},
    BadLog{"EmptyField", M + "t,l0,f0\n0,,2\n", 5, 2, "l0", "expected a finite number, got an empty field"},
    BadLog{"Garbage", M + "t,l0,f0\n0,1,2\n0.2,1,1.2x\n", 6, 3, "f0", "expected a finite number, got '1.2x'"},
    BadLog{"LeadingPlus", M + "t,l0\n0,+1\n", 5, 2, "l0", "got '+1'"},
    BadLog{"LeadingSpace", M + "t,l0\n0, 1\n", 5, 2, "l0", "got ' 1'"},
    BadLog{"GarbageTime", M + "t,l0\n0s,1\n", 5, 1, "t", "got '0s'"},
    // t repeats: non-monotonic, with both values.
    BadLog{"TimeRepeats", M + "t,l0\n0,1\n0.2,1\n0.2,1\n", 7, 1, "t",
           "time not strictly increasing: t = 0.2 s after t = 0.2 s"},
    BadLog{"TimeGoesBack", M + "l0,t\n1,0.4\n1,0.2\n", 6, 2, "t",
           "time not strictly increasing: t = 0.2 s after t = 0.4 s"},
    // t jumps a step: irregular, with step and dt_s.
    BadLog{"TimeSkipsStep", M + "t,l0\n0,1\n0.2,1\n0.6,1\n", 7, 1, "t",
           "irregular time step: t = 0.6 s after t = 0.2 s is a step of 0.4 s, "
           "expected dt_s = 0.2 s (tolerance 2.1e-05 s)"},
    BadLog{"TimeJitterAboveTolerance", M + "t,l0\n0,1\n0.20003,1\n", 6, 1, "t", "irregular time step"},
    BadLog{"BlankLineInData", M + "t,l0\n0,1\n\n0.2,1\n", 6, 0, "", "blank line inside the data"},
    BadLog{"BlankLineAtEnd", M + "t,l0\n0,1\n0.2,1\n\n", 7, 0, "", "blank line inside the data"}),
    bad_log_name);
// clang-format on

// The same error reads as one line a user can act on.
TEST(ParseLog, ErrorTextNamesFileLineColumnAndName) {
  try {
    parse_log(M + "t,f0,f1,f2\n0,1,2,3\n0.2,1,2,nan\n", "runs/a.csv");
    FAIL() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_STREQ(e.what(), "runs/a.csv:6:4: column 'f2': expected a finite number, got 'nan'");
  }
}

// The first error in file order wins over later ones.
TEST(ParseLog, ReportsFirstError) {
  try {
    parse_log(M + "t,l0\n0,x\n0.2,y\n", "a.csv");
    FAIL() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_EQ(e.line(), 5u);
  }
}

}  // namespace
}  // namespace hadynet::datalog
