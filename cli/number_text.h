// One number as text with a printf format (at most 63 characters), for the
// commands' reports.
#pragma once

#include <cstdio>
#include <string>

namespace hadynet::cli {

inline std::string num(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace hadynet::cli
