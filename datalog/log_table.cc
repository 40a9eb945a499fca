#include "datalog/log_table.h"

#include <stdexcept>

namespace hadynet::datalog {

std::optional<std::string> LogMetadata::get(std::string_view key) const {
  for (const auto& [k, v] : entries_) {
    if (k == key) return v;
  }
  return std::nullopt;
}

void LogMetadata::set(std::string_view key, std::string value) {
  for (auto& [k, v] : entries_) {
    if (k == key) {
      v = std::move(value);
      return;
    }
  }
  entries_.emplace_back(std::string(key), std::move(value));
}

std::optional<std::size_t> LogTable::column_index(std::string_view name) const {
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (columns[i] == name) return i;
  }
  return std::nullopt;
}

void LogTable::append_row(const std::vector<double>& row) {
  if (row.size() != columns.size()) {
    throw std::invalid_argument("LogTable::append_row: row has " + std::to_string(row.size()) +
                                " values, the table has " + std::to_string(columns.size()) +
                                " columns");
  }
  values.insert(values.end(), row.begin(), row.end());
}

}  // namespace hadynet::datalog
