#include "datalog/log_table.h"

#include <algorithm>
#include <stdexcept>

namespace hadynet::datalog {

std::optional<std::string> LogMetadata::get(std::string_view key) const {
  const auto i = position(key);
  if (!i) return std::nullopt;
  return entries_[*i].second;
}

std::optional<std::size_t> LogMetadata::position(std::string_view key) const {
  const auto it = position_.find(key);
  if (it == position_.end()) return std::nullopt;
  return it->second;
}

void LogMetadata::set(std::string_view key, std::string value) {
  if (const auto i = position(key)) {
    entries_[*i].second = std::move(value);
    return;
  }
  position_.emplace(std::string(key), entries_.size());
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

std::string declared_unit(std::string_view units_text, std::string_view key) {
  std::size_t pos = 0;
  while (pos < units_text.size()) {
    const std::size_t end = std::min(units_text.find(' ', pos), units_text.size());
    const std::string_view item = units_text.substr(pos, end - pos);
    if (item.size() > key.size() && item.substr(0, key.size()) == key && item[key.size()] == '=')
      return std::string(item.substr(key.size() + 1));
    pos = end + 1;
  }
  return "";
}

}  // namespace hadynet::datalog
