#include "datalog/log_error.h"

#include <utility>

#include "datalog/log_rules.h"

namespace hadynet::datalog {
namespace {

std::string compose(const std::string& file, std::size_t line, std::size_t column,
                    const std::string& column_name, const std::string& message) {
  std::string out = file;
  if (line != 0) {
    if (!out.empty()) out += ':';
    out += std::to_string(line);
    if (column != 0) out += ':' + std::to_string(column);
  }
  if (!out.empty()) out += ": ";
  if (!column_name.empty()) out += "column '" + rules::printable(column_name) + "': ";
  out += message;
  return out;
}

}  // namespace

LogError::LogError(std::string file, std::size_t line, std::size_t column, std::string column_name,
                   std::string message)
    : std::runtime_error(compose(file, line, column, column_name, message)),
      file_(std::move(file)),
      line_(line),
      column_(column),
      column_name_(std::move(column_name)),
      message_(std::move(message)) {}

}  // namespace hadynet::datalog
