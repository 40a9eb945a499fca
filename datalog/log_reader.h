// LogReader: text of a HADYNET log (docs/log-format.md, version 1) -> LogTable.
// Every function either returns a complete, valid table or throws LogError
// naming the file, the 1-based line and field and what was expected; nothing
// partially read is ever returned.
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "datalog/log_error.h"
#include "datalog/log_table.h"

namespace hadynet::datalog {

// Parses a whole log held in memory. `file_for_errors` only labels errors.
LogTable parse_log(std::string_view text, const std::string& file_for_errors);

// Reads and parses the file at `path`; a file that cannot be read (missing,
// a folder, no permission) is a LogError at line 0 with the system's reason.
LogTable read_log(const std::filesystem::path& path);

// The control period of `table` (its '# dt_s:' line), seconds, checked as
// the reader checks it (and nothing else of the metadata): LogError naming
// that line when missing or outside [rules::kMinDtS, rules::kMaxDtS].
double log_dt_s(const LogTable& table, const std::string& file_for_errors);

// Throws LogError at the first value of `columns` (indices into
// table.columns) whose magnitude exceeds `limit`, naming the file line and
// column as the reader would; `reason` ends the message (why the limit).
void check_magnitudes(const LogTable& table, std::span<const std::size_t> columns, double limit,
                      const std::string& file_for_errors, const std::string& reason);

// Derives the column roles from the header of `table` and checks the header
// rules: exactly one 't'; unique names; every name is 't', <prefix><index>
// (prefix [a-z]+, decimal index without leading zeros) or 'aux_<name>'; each
// group's indices appear 0, 1, ..., N-1 in header order; at least one
// observed (non-'u') group. Errors point at the header line of the file form
// of `table` (metadata entries + 1) and the offending column.
ChannelLayout channel_layout(const LogTable& table, const std::string& file_for_errors);

}  // namespace hadynet::datalog
