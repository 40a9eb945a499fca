// hadynet validate: strict check of logs or a dataset folder, and a summary.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "cli/commands.h"
#include "cli/options.h"
#include "datalog/dataset_manifest.h"
#include "datalog/log_error.h"
#include "datalog/log_reader.h"

namespace hadynet::cli {
namespace fs = std::filesystem;

namespace {

struct LogEntry {
  fs::path path;
  std::string split;            // from the manifest, or the parent folder name
  std::optional<long> expected_rows;
};

// Lists the logs of a dataset folder (its manifest.json, checked) or of a
// plain folder (*.csv below it). Returns false after printing an error.
bool list_folder(const fs::path& dir, std::vector<LogEntry>& out) {
  const fs::path manifest_path = dir / "manifest.json";
  if (!fs::exists(manifest_path)) {
    std::vector<fs::path> files;
    for (const auto& e : fs::recursive_directory_iterator(dir))
      if (e.is_regular_file() && e.path().extension() == ".csv") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) out.push_back({f, f.parent_path().filename().string(), std::nullopt});
    return true;
  }
  try {
    for (const auto& log : datalog::read_dataset_manifest(manifest_path).logs) {
      std::optional<long> rows;
      if (log.rows) rows = static_cast<long>(*log.rows);
      out.push_back({dir / log.file, log.split, rows});
    }
  } catch (const datalog::LogError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return false;
  }
  return true;
}

struct ObjectStats {
  long rows = 0;
  double tip_sum_N = 0, palm_sum_N = 0, tip_max_N = 0;
};

}  // namespace

int run_validate(int argc, char** argv) {
  Options opt("validate",
              "Reads every log strictly (docs/log-format.md) and prints a summary: logs, rows, training\n"
              "windows, dynamics states and per-object loadcell statistics. A folder with manifest.json is\n"
              "checked against it. Any error names the file, line and column; the exit code is then 1.",
              "PATH... (log files or dataset folders)");
  opt.value("window", "N", "steps per training window, for the window count", "10");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  const auto window = opt.get_int("window", 1, 100000);
  if (!window) return 2;
  if (opt.positional().empty()) {
    std::fprintf(stderr, "hadynet validate: give at least one log file or dataset folder\n");
    return 2;
  }

  std::vector<LogEntry> entries;
  for (const auto& p : opt.positional()) {
    if (fs::is_directory(p)) {
      if (!list_folder(p, entries)) return 1;
    } else {
      entries.push_back({p, "-", std::nullopt});
    }
  }

  int errors = 0;
  long rows = 0, windows = 0;
  std::map<std::string, long> windows_per_split;
  std::set<std::string> states;
  std::map<std::string, ObjectStats> per_object;
  std::string layout_text;
  for (const auto& entry : entries) {
    try {
      const datalog::LogTable log = datalog::read_log(entry.path);
      const datalog::ChannelLayout layout = datalog::channel_layout(log, entry.path.string());
      if (entry.expected_rows && *entry.expected_rows != static_cast<long>(log.rows())) {
        std::fprintf(stderr, "%s: manifest says %ld rows, the log has %zu\n", entry.path.c_str(), *entry.expected_rows,
                     log.rows());
        ++errors;
        continue;
      }
      if (layout_text.empty()) {
        for (const auto& g : layout.observed) layout_text += g.prefix + "[" + std::to_string(g.columns.size()) + "] ";
        if (layout.command) layout_text += "commands u[" + std::to_string(layout.command->columns.size()) + "] ";
        if (layout.aux) layout_text += "aux[" + std::to_string(layout.aux->columns.size()) + "]";
      }
      rows += static_cast<long>(log.rows());
      const long w = std::max<long>(0, static_cast<long>(log.rows()) - *window);
      windows += w;
      windows_per_split[entry.split] += w;
      states.insert(log.metadata.get("state").value_or(entry.path.string()));
      // Loadcell statistics when the log has the hand's fc group (5 tips + palm).
      auto& stats = per_object[log.metadata.get("object").value_or("?")];
      for (const auto& g : layout.observed) {
        if (g.prefix != "fc") continue;
        for (std::size_t r = 0; r < log.rows(); ++r) {
          double tips = 0, palm = 0;
          for (std::size_t c = 0; c < g.columns.size(); ++c) (c < 5 ? tips : palm) += log.at(r, g.columns[c]);
          stats.tip_sum_N += tips;
          stats.palm_sum_N += palm;
          stats.tip_max_N = std::max(stats.tip_max_N, tips);
        }
        stats.rows += static_cast<long>(log.rows());
      }
    } catch (const datalog::LogError& e) {
      std::fprintf(stderr, "%s\n", e.what());
      ++errors;
    }
  }

  std::printf("logs: %zu (%d invalid), rows: %ld, dynamics states: %zu\n", entries.size(), errors, rows, states.size());
  std::printf("channels: %s\n", layout_text.c_str());
  std::printf("training windows of %lld steps: %ld", *window, windows);
  for (const auto& [split, w] : windows_per_split) std::printf("  [%s: %ld]", split.c_str(), w);
  std::printf("\n");
  if (!per_object.empty() && per_object.begin()->second.rows > 0) {
    std::printf("%-12s %8s %16s %16s %14s\n", "object", "rows", "mean tips (N)", "mean palm (N)", "max tips (N)");
    for (const auto& [object, s] : per_object) {
      if (s.rows == 0) continue;
      std::printf("%-12s %8ld %16.3f %16.3f %14.2f\n", object.c_str(), s.rows, s.tip_sum_N / static_cast<double>(s.rows),
                  s.palm_sum_N / static_cast<double>(s.rows), s.tip_max_N);
    }
  }
  if (errors > 0) {
    std::fprintf(stderr, "hadynet validate: %d of %zu logs invalid\n", errors, entries.size());
    return 1;
  }
  std::printf("all %zu logs valid\n", entries.size());
  return 0;
}

}  // namespace hadynet::cli
