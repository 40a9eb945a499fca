#include "datalog/csv_import.h"

#include <algorithm>
#include <cmath>

#include "datalog/log_error.h"
#include "datalog/log_rules.h"

namespace hadynet::datalog {

using rules::format_number;
using rules::parse_finite_number;

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return s;
}

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

struct Line {
  std::size_t number;  // 1-based line of the file
  std::vector<std::string_view> fields;
};

}  // namespace

LogTable import_csv(std::string_view text, const std::string& file, const CsvImportOptions& o,
                    CsvImportReport* report) {
  if (o.columns.empty()) throw LogError(file, 0, 0, "", "no columns to import");
  if (o.dt_s.has_value() == !o.time_column.empty())
    throw LogError(file, 0, 0, "", "give either a period (dt) or a time column, not both or neither");

  // Lines: header first, then data rows (empty lines skipped).
  std::vector<Line> lines;
  std::size_t number = 0, start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    ++number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.find_first_not_of(" \t") != std::string_view::npos) lines.push_back({number, split_fields(line)});
    start = end + 1;
  }
  if (lines.empty()) throw LogError(file, 0, 0, "", "empty: no header row");
  const Line& header = lines.front();
  const auto column_of = [&](const std::string& name) {
    const auto it = std::find(header.fields.begin(), header.fields.end(), name);
    if (it == header.fields.end()) {
      std::string names;
      for (const auto f : header.fields)
        if (!f.empty()) names += (names.empty() ? "" : ", ") + std::string(f);
      throw LogError(file, header.number, 0, "", "no column '" + name + "' in the header (" + names + ")");
    }
    return static_cast<std::size_t>(it - header.fields.begin());
  };
  std::vector<std::size_t> sources;
  for (const auto& [from, to] : o.columns) sources.push_back(column_of(from));
  const bool timed = !o.time_column.empty();
  const std::size_t time_source = timed ? column_of(o.time_column) : 0;

  const std::size_t data_rows = lines.size() - 1;
  const std::size_t last = o.last_row == 0 ? data_rows : o.last_row;
  if (o.first_row < 1 || last > data_rows || o.first_row > last) {
    throw LogError(file, 0, 0, "", "rows " + std::to_string(o.first_row) + ".." + std::to_string(last) +
                                       " asked, the file has data rows 1.." + std::to_string(data_rows));
  }
  const auto number_at = [&](const Line& line, std::size_t col, const std::string& name) {
    if (col >= line.fields.size())
      throw LogError(file, line.number, col + 1, name, "missing field (the line has " +
                                                           std::to_string(line.fields.size()) + ")");
    const auto v = parse_finite_number(line.fields[col]);
    if (!v) throw LogError(file, line.number, col + 1, name,
                           "expected a finite number, got '" + std::string(line.fields[col]) + "'");
    return *v;
  };
  const std::size_t n = last - o.first_row + 1;
  std::vector<std::vector<double>> channels(sources.size(), std::vector<double>(n));
  std::vector<double> times(n);
  for (std::size_t r = 0; r < n; ++r) {
    const Line& line = lines[o.first_row + r];
    for (std::size_t c = 0; c < sources.size(); ++c) channels[c][r] = number_at(line, sources[c], o.columns[c].first);
    if (timed) times[r] = number_at(line, time_source, o.time_column);
  }

  CsvImportReport rep;
  rep.rows_read = n;
  double dt = 0, t0 = 0;
  std::size_t rows_out = n;
  if (!timed) {
    dt = *o.dt_s;
    if (!(dt > 0)) throw LogError(file, 0, 0, "", "the period must be positive");
  } else {
    if (n < 2) throw LogError(file, 0, 0, o.time_column, "one row: no time step to check");
    std::vector<double> steps(n - 1);
    for (std::size_t r = 1; r < n; ++r) {
      steps[r - 1] = times[r] - times[r - 1];
      if (!(steps[r - 1] > 0))
        throw LogError(file, lines[o.first_row + r].number, time_source + 1, o.time_column,
                       "time not strictly increasing: " + format_number(times[r]) + " s after " +
                           format_number(times[r - 1]) + " s");
    }
    std::vector<double> sorted = steps;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double native = sorted[sorted.size() / 2];  // the clock's period: the median step
    dt = o.resample_dt_s.value_or(native);
    if (!(dt > 0)) throw LogError(file, 0, 0, "", "the resampling period must be positive");
    for (std::size_t r = 0; r < steps.size(); ++r) {
      const double jitter = std::fabs(steps[r] - native) / native;
      if (jitter > o.max_jitter) {
        throw LogError(file, lines[o.first_row + r + 1].number, time_source + 1, o.time_column,
                       "a step of " + format_number(steps[r]) + " s where the period is " + format_number(native) +
                           " s (" + format_number(std::round(jitter * 1000) / 10) + " % off, more than the " +
                           format_number(o.max_jitter * 100) +
                           " % accepted): a lost sample or a stall; import the parts on either side "
                           "separately, or raise the accepted jitter if the clock is that irregular");
      }
      rep.max_jitter = std::max(rep.max_jitter, jitter);
    }
    t0 = times.front();
    rows_out = static_cast<std::size_t>(std::floor((times.back() - t0) / dt + 1e-9)) + 1;
    rep.resampled = true;
  }

  LogTable table;
  table.metadata.set("format", "hadynet-log");
  table.metadata.set("format_version", std::to_string(kFormatVersion));
  table.metadata.set("dt_s", format_number(dt));
  table.metadata.set("source", "hadynet import: " + file);
  table.columns.push_back("t");
  for (const auto& [from, to] : o.columns) table.columns.push_back(to);
  std::vector<double> row(table.columns.size());
  std::size_t seg = 0;  // interpolation segment: times[seg] <= t < times[seg + 1]
  for (std::size_t k = 0; k < rows_out; ++k) {
    row[0] = t0 + static_cast<double>(k) * dt;
    if (!timed) {
      for (std::size_t c = 0; c < channels.size(); ++c) row[c + 1] = channels[c][k];
    } else {
      const double t = row[0];
      while (seg + 2 < n && times[seg + 1] <= t) ++seg;
      const double w = std::clamp((t - times[seg]) / (times[seg + 1] - times[seg]), 0.0, 1.0);
      for (std::size_t c = 0; c < channels.size(); ++c)
        row[c + 1] = channels[c][seg] + w * (channels[c][seg + 1] - channels[c][seg]);
    }
    table.append_row(row);
  }
  rep.rows_written = rows_out;
  rep.dt_s = dt;
  if (report != nullptr) *report = rep;
  return table;
}

}  // namespace hadynet::datalog
