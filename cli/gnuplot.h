// Runs gnuplot on a script that writes one PNG. Returns an empty string on
// success, else a message for the user (gnuplot missing, or it failed).
#pragma once

#include <string>

namespace hadynet::cli {

std::string run_gnuplot(const std::string& script, const std::string& png);

// A gnuplot string literal (single quotes, quotes doubled) for titles and paths.
std::string gnuplot_quote(const std::string& text);

}  // namespace hadynet::cli
