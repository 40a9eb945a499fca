#include "cli/gnuplot.h"

#include <cstdio>
#include <filesystem>

namespace hadynet::cli {

std::string gnuplot_quote(const std::string& text) {
  std::string q = "'";
  for (char c : text) {
    if (c == '\'') q += '\'';
    q += c;
  }
  return q + "'";
}

std::string run_gnuplot(const std::string& script, const std::string& png) {
  std::error_code ec;
  std::filesystem::remove(png, ec);
  FILE* gp = popen("gnuplot 2>&1", "w");
  if (gp == nullptr) return "cannot start gnuplot (install gnuplot-nox: scripts/setup.sh)";
  std::fwrite(script.data(), 1, script.size(), gp);
  const int status = pclose(gp);
  if (status != 0 || !std::filesystem::exists(png)) return "gnuplot failed to write " + png;
  return "";
}

}  // namespace hadynet::cli
