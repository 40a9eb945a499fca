// The one error type of the log library: where in which file, and what was
// found versus what was expected.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace hadynet::datalog {

// what() is "FILE:LINE:COL: column 'NAME': MESSAGE"; each location part is
// left out when it is empty/0, the "column '...': " part when column_name is
// empty. Example: "runs/a.csv:12:5: column 'f2': expected a finite number, got 'nan'".
class LogError : public std::runtime_error {
 public:
  // line: 1-based line of the file, 0 = the whole file.
  // column: 1-based field index on that line, 0 = not about one field.
  LogError(std::string file, std::size_t line, std::size_t column, std::string column_name,
           std::string message);

  const std::string& file() const noexcept { return file_; }
  std::size_t line() const noexcept { return line_; }
  std::size_t column() const noexcept { return column_; }
  const std::string& column_name() const noexcept { return column_name_; }
  // The message alone, without the location prefix.
  const std::string& message() const noexcept { return message_; }

 private:
  std::string file_;
  std::size_t line_;
  std::size_t column_;
  std::string column_name_;
  std::string message_;
};

}  // namespace hadynet::datalog
