#include "datalog/log_error.h"

#include <gtest/gtest.h>

namespace hadynet::datalog {
namespace {

// what() carries file, line, column and column name in front of the message.
TEST(LogError, WhatHasFullLocation) {
  const LogError error("runs/a.csv", 12, 5, "f2", "expected a finite number, got 'nan'");
  EXPECT_STREQ(error.what(), "runs/a.csv:12:5: column 'f2': expected a finite number, got 'nan'");
  EXPECT_EQ(error.file(), "runs/a.csv");
  EXPECT_EQ(error.line(), 12u);
  EXPECT_EQ(error.column(), 5u);
  EXPECT_EQ(error.column_name(), "f2");
  EXPECT_EQ(error.message(), "expected a finite number, got 'nan'");
}

// Parts that are 0 or empty are left out of what().
TEST(LogError, WhatOmitsZeroParts) {
  EXPECT_STREQ(LogError("a.csv", 3, 0, "", "m").what(), "a.csv:3: m");
  EXPECT_STREQ(LogError("a.csv", 0, 0, "", "empty file").what(), "a.csv: empty file");
  EXPECT_STREQ(LogError("", 4, 2, "l0", "m").what(), "4:2: column 'l0': m");
}

}  // namespace
}  // namespace hadynet::datalog
