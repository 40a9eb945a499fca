// Internal: the rules of format version 1 that the reader and the writer
// share, so that the writer never produces a file the reader rejects.
// Not part of the public API.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "datalog/log_table.h"

namespace hadynet::datalog::rules {

inline constexpr std::string_view kFormatName = "hadynet-log";

// Throws LogError at `line` unless `key` is [a-z0-9_]+.
void check_metadata_key(std::string_view key, const std::string& file, std::size_t line);

// Line of the header in the file form of `table`: metadata lines come first,
// one per entry, then the header. Data row r is on header_line + 1 + r.
inline std::size_t header_line(const LogTable& table) {
  return table.metadata.entries().size() + 1;
}

// The range of `dt_s`, seconds: a control period from a nanosecond to about
// eleven days. Outside it the time checks and every tool that divides by
// dt_s lose their meaning (a denormal dt_s overflows 1 / dt_s).
inline constexpr double kMinDtS = 1e-9;
inline constexpr double kMaxDtS = 1e6;

// Checks `dt_s` alone (present, within [kMinDtS, kMaxDtS]) and returns it in
// seconds; the error points at its line, or at the whole file when missing.
double check_dt_s(const LogMetadata& metadata, const std::string& file);

// Checks `format`, `format_version` and `dt_s` (present, valid) and returns
// dt_s in seconds. Errors point at the entry's line (its position + 1) or at
// the whole file (line 0) when a key is missing.
double check_required_metadata(const LogMetadata& metadata, const std::string& file);

// The whole field is a finite double in std::from_chars general syntax
// (no leading '+', no spaces, no nan/inf), else nullopt.
std::optional<double> parse_finite_number(std::string_view field);

// Shortest text that reads back to exactly `value` (std::to_chars).
std::string format_number(double value);
// Same, appended to `out` without a temporary string.
void append_number(std::string& out, double value);

// 't' of one row against the previous row: strictly increasing, and
// t - t_prev == dt_s within time_step_tolerance_s(dt_s). Throws LogError at
// (line, column) naming column 't'.
void check_time_step(double t_prev_s, double t_s, double dt_s, const std::string& file,
                     std::size_t line, std::size_t column);
inline double time_step_tolerance_s(double dt_s) { return 1e-6 + 1e-4 * dt_s; }

// Offset of the first byte of `text` that is not part of well-formed UTF-8,
// or npos.
std::size_t first_invalid_utf8(std::string_view text);
// "invalid UTF-8 at byte K of the line; ..." for the byte at `offset`.
std::string invalid_utf8_message(std::string_view text, std::size_t offset);

// `text` with every ASCII control byte (NUL, CR, ESC, ...) written as \xHH,
// so that a message shows it and no terminal or C string cuts it short.
std::string printable(std::string_view text);

// `text` in single quotes for a message (printable()), cut to a readable
// length.
std::string quoted(std::string_view text);

}  // namespace hadynet::datalog::rules
