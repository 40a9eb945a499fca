// From a plain column CSV (a header row of names, then rows of numbers) to a
// HADYNET log (docs/log-format.md): chosen columns renamed to log channels
// (u0, y0, ...; any numbered groups), a regular time axis, the required
// metadata. `hadynet import` is the command around it.
//
// Time: either the rows are regular at `dt_s` (t = k dt_s), or a column
// holds timestamps in seconds. Measured timestamps jitter; a log's time axis
// is regular (docs/log-format.md, section 5). Steps within `max_jitter` of
// the median step (a fraction of it) are accepted and every channel is
// linearly interpolated onto t0 + k dt (dt: the median step, or `resample_dt_s`);
// a larger deviation (a lost sample, a stall, a clock jump) is an error that
// names the line and the step found, never silently bridged.
//
// Text rules: fields separated by `,`; surrounding double quotes and spaces
// of a field are dropped; empty lines are skipped; CR before LF is accepted.
// A mapped (or the time) column's field must be a finite number
// (parse_finite_number); the other columns are not read, so they may be
// empty (e.g. a sample time given only in the first row).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "datalog/log_table.h"

namespace hadynet::datalog {

struct CsvImportOptions {
  // CSV column -> log channel, in the log's column order (after `t`).
  std::vector<std::pair<std::string, std::string>> columns;
  std::optional<double> dt_s;            // regular rows at this period (s); or:
  std::string time_column;               // timestamps (s) in this CSV column
  double max_jitter = 0.1;               // with time_column: max |step - median step| / median step
  std::optional<double> resample_dt_s;   // with time_column: the grid's period (default: the median step)
  std::size_t first_row = 1;             // data rows used: first..last (1-based, inclusive;
  std::size_t last_row = 0;              //   last 0: to the end)
};

struct CsvImportReport {
  std::size_t rows_read = 0;     // data rows used
  std::size_t rows_written = 0;  // rows of the log
  double dt_s = 0;               // the log's period
  double max_jitter = 0;         // with time_column: largest |step - median| / median found
  bool resampled = false;        // with time_column: interpolated onto the grid
};

// Throws LogError naming `file`, the line and the column on any problem.
// The result has the metadata format, format_version, dt_s and source, and
// the columns t then the mapped channels; check_log() rules hold for it.
LogTable import_csv(std::string_view text, const std::string& file, const CsvImportOptions& options,
                    CsvImportReport* report = nullptr);

}  // namespace hadynet::datalog
