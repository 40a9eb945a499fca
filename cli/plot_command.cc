// hadynet plot: one PNG per log with a panel per channel group (l, f, fc, th,
// u, aux ...) against time, drawn by gnuplot. The log is read strictly first.
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli/commands.h"
#include "cli/options.h"
#include "datalog/log_error.h"
#include "datalog/log_reader.h"
#include "datalog/log_writer.h"

namespace hadynet::cli {
namespace fs = std::filesystem;

namespace {

// gnuplot script: inline data block, then one panel per group.
std::string plot_script(const datalog::LogTable& log, const datalog::ChannelLayout& layout,
                        const std::string& title, const fs::path& png) {
  std::vector<datalog::ChannelGroup> groups = layout.observed;
  if (layout.command) groups.push_back(*layout.command);
  if (layout.aux) groups.push_back(*layout.aux);
  const std::string units = log.metadata.get("units").value_or("");
  auto unit_of = [&](const std::string& prefix) -> std::string {
    const std::string unit = datalog::declared_unit(units, prefix);
    return unit.empty() ? "" : " [" + unit + "]";
  };

  std::string s;
  s += "$log << EOD\n";
  for (std::size_t r = 0; r < log.rows(); ++r) {
    for (std::size_t c = 0; c < log.columns.size(); ++c) {
      if (c) s += ' ';
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.9g", log.at(r, c));
      s += buf;
    }
    s += '\n';
  }
  s += "EOD\n";
  const int panels = static_cast<int>(groups.size());
  s += "set terminal pngcairo size 1200," + std::to_string(220 * panels + 60) + " font 'sans,9' noenhanced\n";
  s += "set output '" + png.string() + "'\n";
  s += "set multiplot layout " + std::to_string(panels) + ",1 title '" + title + "'\n";
  s += "set key outside right top spacing 0.8\nset grid\nset lmargin 10\nset rmargin 14\n";
  const std::size_t t_col = layout.time_column + 1;  // gnuplot columns are 1-based
  for (int p = 0; p < panels; ++p) {
    const auto& g = groups[p];
    s += "set ylabel '" + g.prefix + unit_of(g.prefix) + "'\n";
    s += p + 1 == panels ? "set xlabel 't [s]'\n" : "unset xlabel\n";
    s += "plot ";
    for (std::size_t i = 0; i < g.columns.size(); ++i) {
      if (i) s += ", ";
      s += "$log using " + std::to_string(t_col) + ":" + std::to_string(g.columns[i] + 1) +
           " with lines lw 1 title '" + log.columns[g.columns[i]] + "'";
    }
    s += "\n";
  }
  s += "unset multiplot\n";
  return s;
}

}  // namespace

int run_plot(int argc, char** argv) {
  Options opt("plot",
              "Draws a log as a PNG with gnuplot: one panel per channel group (muscle lengths, tensions,\n"
              "loadcells, wrist angles, commands, aux channels) against time.",
              "LOG [--out PNG]");
  opt.value("out", "PNG", "output image (default: the log's path with .png)");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (opt.positional().size() != 1) {
    std::fprintf(stderr, "hadynet plot: give exactly one log file\n");
    return 2;
  }
  const fs::path path = opt.positional().front();
  const fs::path png = opt.has("out") ? fs::path(opt.get("out")) : fs::path(path).replace_extension(".png");
  try {
    const auto log = datalog::read_log(path);
    const auto layout = datalog::channel_layout(log, path.string());
    std::string title = path.filename().string();
    if (auto state = log.metadata.get("state")) title += "  (state " + *state + ")";
    const std::string script = plot_script(log, layout, title, png);
    FILE* gp = popen("gnuplot", "w");
    if (!gp) {
      std::fprintf(stderr, "hadynet plot: cannot start gnuplot (install gnuplot-nox: scripts/setup.sh)\n");
      return 1;
    }
    std::fwrite(script.data(), 1, script.size(), gp);
    if (pclose(gp) != 0 || !fs::exists(png)) {
      std::fprintf(stderr, "hadynet plot: gnuplot failed to write %s\n", png.c_str());
      return 1;
    }
    std::printf("wrote %s\n", png.c_str());
  } catch (const datalog::LogError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
