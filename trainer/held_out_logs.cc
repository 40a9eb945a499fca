#include "trainer/held_out_logs.h"

#include <cstddef>
#include <stdexcept>

#include "datalog/log_reader.h"
#include "datalog/log_writer.h"

namespace hadynet::trainer {

std::vector<StoredLog> held_out_logs(const std::vector<std::string>& paths, const WindowDataset& data,
                                     const WindowDataset::Split& split) {
  std::vector<StoredLog> out;
  int previous_sequence = -1;
  for (const int id : split.held_out) {  // sequence-major, start ascending
    const WindowDataset::Window& w = data.window(id);
    if (w.sequence == previous_sequence) continue;
    previous_sequence = w.sequence;
    if (w.sequence < 0 || static_cast<std::size_t>(w.sequence) >= paths.size())
      throw std::invalid_argument("held_out_logs: a window's sequence has no path");
    const std::string& path = paths[static_cast<std::size_t>(w.sequence)];
    const datalog::LogTable log = datalog::read_log(path);
    const auto first = static_cast<std::size_t>(w.start - 1);
    datalog::LogTable part;
    part.metadata = log.metadata;
    part.columns = log.columns;
    const std::size_t width = log.columns.size();
    part.values.assign(log.values.begin() + static_cast<std::ptrdiff_t>(first * width), log.values.end());
    const std::string name = path + " rows " + std::to_string(first) + ".." + std::to_string(log.rows() - 1);
    out.push_back({name, datalog::format_log(part, name)});
  }
  return out;
}

bool contains_rows(const datalog::LogTable& log, const datalog::LogTable& part) {
  if (part.rows() == 0 || part.rows() > log.rows()) return false;
  std::vector<std::size_t> column_in_log;  // part's column j is log's column column_in_log[j]
  for (const auto& name : part.columns) {
    const auto c = log.column_index(name);
    if (!c) return false;
    column_in_log.push_back(*c);
  }
  const auto rows_equal = [&](std::size_t log_row, std::size_t part_row) {
    for (std::size_t j = 0; j < part.columns.size(); ++j)
      if (log.at(log_row, column_in_log[j]) != part.at(part_row, j)) return false;
    return true;
  };
  for (std::size_t start = 0; start + part.rows() <= log.rows(); ++start) {
    if (!rows_equal(start, 0)) continue;
    std::size_t k = 1;
    while (k < part.rows() && rows_equal(start + k, k)) ++k;
    if (k == part.rows()) return true;
  }
  return false;
}

}  // namespace hadynet::trainer
