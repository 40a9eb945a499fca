// hadynet import: a plain column CSV -> a HADYNET log (datalog/csv_import.h),
// so that measured data from anywhere goes through every tool.
#include <cstdio>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/options.h"
#include "datalog/csv_import.h"
#include "datalog/log_limits.h"
#include "datalog/log_reader.h"
#include "datalog/log_writer.h"

namespace hadynet::cli {

namespace {

// "a=b" -> {a, b}; false when there is no '=' or a side is empty.
bool split_pair(const std::string& text, std::pair<std::string, std::string>& out) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) return false;
  out = {text.substr(0, eq), text.substr(eq + 1)};
  return true;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::string text;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<std::size_t>(in.gcount()));
    if (text.size() > datalog::kMaxLogBytes)
      throw std::runtime_error(path + ": more than " + std::to_string(datalog::kMaxLogBytes) + " bytes");
  }
  return text;
}

}  // namespace

int run_import(int argc, char** argv) {
  Options opt("import",
              "Turns a plain column CSV (a header row of names, then rows of numbers; quoted names, empty\n"
              "fields in unused columns and CRLF are fine) into a HADYNET log (docs/log-format.md): the\n"
              "--column mappings become the log's channels, in their order. Time: --dt for regular rows, or\n"
              "--time COLUMN for timestamps in seconds: steps within --max-jitter of the median step are\n"
              "accepted and every channel is linearly interpolated onto a regular grid (a larger step, e.g.\n"
              "a lost sample, is an error naming its line). The log is checked and written atomically.",
              "CSV --out LOG --column SRC=CHANNEL... (--dt S | --time COLUMN) [options]");
  opt.value("out", "LOG", "log file to write");
  opt.repeated("column", "SRC=CHANNEL", "a CSV column and its channel name in the log, e.g. uEst=u0 (repeat)");
  opt.value("dt", "S", "the rows are regular at S seconds");
  opt.value("time", "COLUMN", "timestamps (s) of each row, resampled onto a regular grid");
  opt.value("max-jitter", "F", "with --time: largest accepted |step - median step| / median step", "0.1");
  opt.value("resample", "S", "with --time: the grid's period (default: the median step)");
  opt.value("rows", "A:B", "import data rows A..B only (1-based, inclusive; B empty: to the end)");
  opt.value("state", "NAME", "metadata 'state': the dynamics state (one PB per state; default: the file stem)");
  opt.value("object", "NAME", "metadata 'object'");
  opt.repeated("meta", "KEY=VALUE", "any other metadata entry, e.g. delta_groups=y or units=t=s (repeat)");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (opt.positional().size() != 1 || !opt.has("out") || !opt.has("column") || opt.has("dt") == opt.has("time")) {
    std::fprintf(stderr, "hadynet import: give one CSV, --out, --column and either --dt or --time (see --help)\n");
    return 2;
  }
  datalog::CsvImportOptions io;
  for (const auto& c : opt.all("column")) {
    std::pair<std::string, std::string> p;
    if (!split_pair(c, p)) {
      std::fprintf(stderr, "hadynet import: --column expects SRC=CHANNEL, got '%s'\n", c.c_str());
      return 2;
    }
    io.columns.push_back(p);
  }
  if (opt.has("dt")) {
    const auto dt = opt.get_double("dt", 1e-9, 1e6);
    if (!dt) return 2;
    io.dt_s = *dt;
  } else {
    io.time_column = opt.get("time");
    const auto jitter = opt.get_double("max-jitter", 0.0, 10.0);
    if (!jitter) return 2;
    io.max_jitter = *jitter;
    if (opt.has("resample")) {
      const auto r = opt.get_double("resample", 1e-9, 1e6);
      if (!r) return 2;
      io.resample_dt_s = *r;
    }
  }
  if (opt.has("rows")) {
    const std::string rows = opt.get("rows");
    const auto colon = rows.find(':');
    try {
      std::size_t used = 0;
      io.first_row = std::stoul(rows.substr(0, colon), &used);
      if (colon == std::string::npos || used != colon) throw std::invalid_argument("");
      const std::string tail = rows.substr(colon + 1);
      io.last_row = tail.empty() ? 0 : std::stoul(tail, &used);
      if (!tail.empty() && used != tail.size()) throw std::invalid_argument("");
    } catch (const std::exception&) {
      std::fprintf(stderr, "hadynet import: --rows expects A:B (e.g. 1:1024), got '%s'\n", rows.c_str());
      return 2;
    }
  }
  std::vector<std::pair<std::string, std::string>> meta;
  for (const auto& m : opt.all("meta")) {
    std::pair<std::string, std::string> p;
    if (!split_pair(m, p)) {
      std::fprintf(stderr, "hadynet import: --meta expects KEY=VALUE, got '%s'\n", m.c_str());
      return 2;
    }
    meta.push_back(p);
  }

  try {
    const std::string csv = opt.positional().front();
    datalog::CsvImportReport report;
    datalog::LogTable table = datalog::import_csv(read_text(csv), csv, io, &report);
    if (opt.has("state")) table.metadata.set("state", opt.get("state"));
    if (opt.has("object")) table.metadata.set("object", opt.get("object"));
    for (const auto& [k, v] : meta) table.metadata.set(k, v);
    const std::string out = opt.get("out");
    datalog::write_log(out, table);  // checks the log's rules (channel names, time axis, metadata keys)
    datalog::channel_layout(datalog::read_log(out), out);  // and that every tool reads it back
    std::printf("%s: %zu rows -> %s: %zu rows, dt_s %g", csv.c_str(), report.rows_read, out.c_str(),
                report.rows_written, report.dt_s);
    if (report.resampled) std::printf(", resampled from timestamps (largest jitter %.2g %%)", 100 * report.max_jitter);
    std::printf("\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet import: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
