// import_csv (datalog/csv_import.h): plain CSVs into logs; bad input named by
// file, line and column; jittered timestamps resampled, gaps refused.
#include "datalog/csv_import.h"

#include <gtest/gtest.h>

#include <cmath>

#include "datalog/log_error.h"
#include "datalog/log_reader.h"
#include "datalog/log_writer.h"

namespace hadynet::datalog {
namespace {

CsvImportOptions regular(double dt) {
  CsvImportOptions o;
  o.columns = {{"uEst", "u0"}, {"yEst", "y0"}};
  o.dt_s = dt;
  return o;
}

// The Cascaded Tanks file's shape: quoted names, a trailing comma, a sample
// time only in the first row, a blank last line, CRLF.
TEST(CsvImport, QuotedHeaderTrailingCommaAndSparseColumns) {
  const std::string text =
      "\"uEst\",\"uVal\",\"yEst\",\"yVal\",\"Ts\",\r\n3.25,0.97,5.2,4.9,4,\r\n3.5,1.0,5.3,4.8,,\r\n\r\n";
  CsvImportReport r;
  const LogTable t = import_csv(text, "tanks.csv", regular(4), &r);
  ASSERT_EQ(t.columns, (std::vector<std::string>{"t", "u0", "y0"}));
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.at(1, 0), 4.0);
  EXPECT_EQ(t.at(1, 1), 3.5);
  EXPECT_EQ(t.at(1, 2), 5.3);
  EXPECT_EQ(*t.metadata.get("dt_s"), "4");
  EXPECT_EQ(r.rows_written, 2u);
  // The result is a valid log: it round-trips through the format's checks.
  const LogTable back = parse_log(format_log(t), "x.csv");
  EXPECT_EQ(back.values, t.values);
}

TEST(CsvImport, RowRange) {
  CsvImportOptions o = regular(1);
  o.first_row = 2;
  o.last_row = 3;
  const LogTable t = import_csv("uEst,yEst\n1,10\n2,20\n3,30\n4,40\n", "a.csv", o);
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.at(0, 1), 2.0);
  EXPECT_EQ(t.at(1, 2), 30.0);
  o.last_row = 9;
  EXPECT_THROW(import_csv("uEst,yEst\n1,10\n", "a.csv", o), LogError);
}

TEST(CsvImport, BadFieldNamesFileLineAndColumn) {
  try {
    import_csv("uEst,yEst\n1,10\n2,oops\n", "a.csv", regular(1));
    FAIL() << "no error";
  } catch (const LogError& e) {
    EXPECT_EQ(e.line(), 3u);
    EXPECT_EQ(e.column(), 2u);
    EXPECT_EQ(e.column_name(), "yEst");
    EXPECT_NE(std::string(e.what()).find("got 'oops'"), std::string::npos) << e.what();
  }
  try {
    import_csv("u,y\n1,10\n", "a.csv", regular(1));
    FAIL() << "no error";
  } catch (const LogError& e) {
    EXPECT_NE(std::string(e.what()).find("no column 'uEst' in the header (u, y)"), std::string::npos) << e.what();
  }
}

// Timestamps with +-3 % jitter around 0.5 s: accepted and interpolated onto
// t0 + k 0.5; a linear signal stays exactly linear (tolerance 1e-12: the
// interpolation of a line is the line, up to rounding).
TEST(CsvImport, JitteredTimestampsAreResampled) {
  std::string text = "time,u,y\n";
  const double jitter[] = {0, 0.01, -0.015, 0.012, -0.008, 0.015, 0, -0.01, 0.005, 0};
  for (int k = 0; k < 10; ++k) {
    const double t = 0.5 * k + jitter[k];
    text += std::to_string(t) + "," + std::to_string(2 * t) + "," + std::to_string(1 - t) + "\n";
  }
  CsvImportOptions o;
  o.columns = {{"u", "u0"}, {"y", "y0"}};
  o.time_column = "time";
  CsvImportReport r;
  const LogTable t = import_csv(text, "j.csv", o, &r);
  EXPECT_TRUE(r.resampled);
  EXPECT_NEAR(r.dt_s, 0.5, 0.02);
  EXPECT_GT(r.max_jitter, 0.02);
  EXPECT_LT(r.max_jitter, 0.1);
  for (std::size_t k = 0; k < t.rows(); ++k) {
    const double tk = t.at(k, 0);
    EXPECT_NEAR(t.at(k, 1), 2 * tk, 1e-12);
    EXPECT_NEAR(t.at(k, 2), 1 - tk, 1e-12);
  }
  EXPECT_NO_THROW(parse_log(format_log(t), "x.csv"));
}

// A lost sample (a double step) is refused at its line, never bridged.
TEST(CsvImport, AGapIsAnErrorNamingItsLine) {
  CsvImportOptions o;
  o.columns = {{"y", "y0"}};
  o.time_column = "time";
  try {
    import_csv("time,y\n0,1\n1,1\n2,1\n4,1\n5,1\n", "g.csv", o);
    FAIL() << "no error";
  } catch (const LogError& e) {
    EXPECT_EQ(e.line(), 5u);
    EXPECT_NE(std::string(e.what()).find("a step of 2 s where the period is 1 s"), std::string::npos) << e.what();
  }
}

TEST(CsvImport, TimeAndPeriodAreExclusive) {
  CsvImportOptions o = regular(1);
  o.time_column = "uEst";
  EXPECT_THROW(import_csv("uEst,yEst\n1,2\n", "a.csv", o), LogError);
}

}  // namespace
}  // namespace hadynet::datalog
