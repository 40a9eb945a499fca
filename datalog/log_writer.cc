#include "datalog/log_writer.h"


#include <algorithm>
#include <cmath>

#include "datalog/atomic_file.h"
#include "datalog/log_reader.h"
#include "datalog/log_rules.h"

namespace hadynet::datalog {
namespace {

void check_metadata_entries(const LogMetadata& metadata, const std::string& file) {
  const auto& entries = metadata.entries();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& [key, value] = entries[i];
    rules::check_metadata_key(key, file, i + 1);
    if (value.find_first_of("\r\n") != std::string::npos) {
      throw LogError(file, i + 1, 0, "",
                     "metadata " + rules::quoted(key) +
                         ": value holds a line break; expected a single line");
    }
  }
}

}  // namespace

std::string format_log(const LogTable& table, const std::string& file_for_errors) {
  const std::string& file = file_for_errors;
  check_metadata_entries(table.metadata, file);
  const double dt_s = rules::check_required_metadata(table.metadata, file);
  const ChannelLayout layout = channel_layout(table, file);

  const std::size_t columns = table.columns.size();
  const std::size_t header_line = rules::header_line(table);
  if (table.values.size() % columns != 0) {
    throw LogError(file, 0, 0, "",
                   "table holds " + std::to_string(table.values.size()) +
                       " values; expected a multiple of the " + std::to_string(columns) +
                       " columns");
  }
  const std::size_t rows = table.rows();
  if (rows == 0) {
    throw LogError(file, 0, 0, "",
                   "no data rows after the header (line " + std::to_string(header_line) +
                       "); expected at least one");
  }

  std::string out;
  out.reserve(64 * table.metadata.entries().size() + 8 * columns + 16 * table.values.size());
  for (const auto& [key, value] : table.metadata.entries()) {
    out += "# ";
    out += key;
    out += ':';
    if (!value.empty()) {
      out += ' ';
      out += value;
    }
    out += '\n';
  }
  for (std::size_t c = 0; c < columns; ++c) {
    if (c > 0) out += ',';
    out += table.columns[c];
  }
  out += '\n';
  // Metadata values and aux_ names are free text: the reader wants UTF-8.
  if (const std::size_t bad = rules::first_invalid_utf8(out); bad != std::string::npos) {
    const auto before = std::string_view(out).substr(0, bad);
    const auto line = static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n')) + 1;
    throw LogError(file, line, 0, "", rules::invalid_utf8_message(out, bad));
  }

  for (std::size_t r = 0; r < rows; ++r) {
    const std::size_t line = header_line + 1 + r;
    for (std::size_t c = 0; c < columns; ++c) {
      const double value = table.at(r, c);
      if (!std::isfinite(value)) {
        throw LogError(file, line, c + 1, table.columns[c],
                       "not written: the value to write is " + rules::format_number(value) +
                           ", and a log holds finite numbers only (the computation that produced it "
                           "failed)");
      }
      if (c > 0) out += ',';
      rules::append_number(out, value);
    }
    out += '\n';
    if (r > 0) {
      rules::check_time_step(table.at(r - 1, layout.time_column), table.at(r, layout.time_column),
                             dt_s, file, line, layout.time_column + 1);
    }
  }
  return out;
}

void write_log(const std::filesystem::path& path, const LogTable& table) {
  const std::string file = path.string();
  const std::string text = format_log(table, file);
  try {
    write_file_atomically(path, text);
  } catch (const AtomicWriteError& e) {
    throw LogError(file, 0, 0, "", std::string("cannot write log file: ") + e.what());
  }
}

}  // namespace hadynet::datalog
