// LogWriter: LogTable -> text of a HADYNET log (docs/log-format.md, version 1).
// The writer checks the table against the same rules as the reader, so
// parse_log(format_log(x)) == x exactly (every double bit for bit, metadata
// in order) and it never writes a file the reader would reject.
#pragma once

#include <filesystem>
#include <string>

#include "datalog/log_error.h"
#include "datalog/log_table.h"

namespace hadynet::datalog {

// The file text of `table`. Numbers are the shortest text that reads back to
// the same double (std::to_chars). Throws LogError if the table breaks a
// format rule (missing/invalid required metadata, a metadata value holding a
// line break, a bad header, values.size() not rows x columns, zero rows, a
// non-finite value, irregular t); its line/column are those the offending
// item would have in the output, its file is `file_for_errors`.
std::string format_log(const LogTable& table, const std::string& file_for_errors = "<log table>");

// Writes format_log(table) to `path` atomically: the text goes to a new
// temporary file in the same folder, is flushed to disk (fsync), then renamed
// over `path`. A writer killed at any point leaves either the old file or the
// complete new one under `path` (never a partial file); on a LogError nothing
// under `path` changes and the temporary file is removed.
void write_log(const std::filesystem::path& path, const LogTable& table);

}  // namespace hadynet::datalog
