// The firmware tests' tolerances, read from the one table in
// docs/tolerances.md (rows "| `key` | value | ... |"), so that the numbers the
// tests enforce are the numbers the documentation states.
#pragma once

#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

namespace hadynet::test {

// Value of `key` in docs/tolerances.md; throws std::runtime_error if the
// table or the key is missing, or the value is not a number.
inline double tolerance(const std::string& key) {
  static const std::map<std::string, double> table = [] {
    std::ifstream in(HADYNET_TOLERANCES_MD);
    if (!in) throw std::runtime_error(std::string("cannot read ") + HADYNET_TOLERANCES_MD);
    std::map<std::string, double> t;
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("| `", 0) != 0) continue;
      const auto key_end = line.find('`', 3);
      const auto cell = line.find('|', key_end);
      const auto cell_end = line.find('|', cell + 1);
      if (key_end == std::string::npos || cell == std::string::npos || cell_end == std::string::npos)
        throw std::runtime_error("docs/tolerances.md: malformed row: " + line);
      std::istringstream value(line.substr(cell + 1, cell_end - cell - 1));
      double v = 0;
      if (!(value >> v)) throw std::runtime_error("docs/tolerances.md: no number in row: " + line);
      t[line.substr(3, key_end - 3)] = v;
    }
    return t;
  }();
  const auto it = table.find(key);
  if (it == table.end()) throw std::runtime_error("docs/tolerances.md has no row `" + key + "`");
  return it->second;
}

}  // namespace hadynet::test
