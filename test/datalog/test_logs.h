// Shared inputs of the datalog tests.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "datalog/log_table.h"

namespace hadynet::datalog::test {

// The three required metadata lines (lines 1-3), so a header follows on line 4
// and the first data row is line 5.
inline const std::string kRequiredMetadata =
    "# format: hadynet-log\n"
    "# format_version: 1\n"
    "# dt_s: 0.2\n";

// The Musashi hand's header (docs/architecture.md §2): 27 observed channels, 8 commands.
inline std::string hand_header() {
  std::string header = "t";
  const auto group = [&](const std::string& prefix, int n) {
    for (int i = 0; i < n; ++i) header += "," + prefix + std::to_string(i);
  };
  group("l", 8);
  group("f", 8);
  group("fc", 9);
  group("th", 2);
  group("u", 8);
  return header;
}

// A valid table with the required metadata and the given columns, no rows.
inline LogTable empty_table(std::vector<std::string> columns) {
  LogTable table;
  table.metadata.set("format", "hadynet-log");
  table.metadata.set("format_version", "1");
  table.metadata.set("dt_s", "0.2");
  table.columns = std::move(columns);
  return table;
}

}  // namespace hadynet::datalog::test
