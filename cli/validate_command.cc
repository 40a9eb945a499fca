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
#include "datalog/robot_profile.h"

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

// Per object: the mean and the largest value of each contact sum of the
// logs' robot profile (datalog/robot_profile.h), in the channels' unit.
struct ObjectStats {
  long rows = 0;
  std::map<std::string, double> sum, max;  // by contact-sum name
};

// The unit the log's `units` metadata gives the group of `channel` ("fc3"
// -> "N" from "... fc=N ..."); empty when it says nothing.
std::string unit_of(const datalog::LogTable& log, const std::string& channel) {
  return datalog::declared_unit(log.metadata.get("units").value_or(""),
                                channel.substr(0, channel.find_first_of("0123456789")));
}

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
  std::vector<datalog::ContactSum> contact_sums;  // the first log's; logs with others are not summed
  std::string unit;                               // of the contact sums' channels, from `units`
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
      // Contact statistics from the profile's contact sums (the hand: tips, palm).
      const datalog::RobotProfile profile = datalog::read_profile(log.metadata, entry.path.string());
      if (contact_sums.empty()) {
        contact_sums = profile.contact_sums;
        if (!contact_sums.empty()) unit = unit_of(log, contact_sums.front().channels.front());
      }
      auto& stats = per_object[log.metadata.get("object").value_or("?")];
      if (!profile.contact_sums.empty() && profile.contact_sums == contact_sums) {
        std::vector<std::vector<std::size_t>> columns;
        for (const datalog::ContactSum& c : contact_sums) {
          columns.emplace_back();
          for (const std::string& name : c.channels) {
            const auto col = log.column_index(name);
            if (!col) throw datalog::LogError(entry.path.string(), 0, 0, name, "contact sum '" + c.name + "' names channel '" + name + "', which the log lacks");
            columns.back().push_back(*col);
          }
        }
        for (std::size_t r = 0; r < log.rows(); ++r) {
          for (std::size_t k = 0; k < contact_sums.size(); ++k) {
            double v = 0;
            for (std::size_t col : columns[k]) v += log.at(r, col);
            stats.sum[contact_sums[k].name] += v;
            auto [it, fresh] = stats.max.emplace(contact_sums[k].name, v);
            if (!fresh) it->second = std::max(it->second, v);
          }
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
  if (!contact_sums.empty()) {
    std::printf("%-12s %8s", "object", "rows");
    for (const char* what : {"mean", "max"}) {
      for (const auto& c : contact_sums) {
        const std::string head = std::string(what) + " " + c.name + (unit.empty() ? "" : " (" + unit + ")");
        std::printf(" %16s", head.c_str());
      }
    }
    std::printf("\n");
    for (const auto& [object, s] : per_object) {
      if (s.rows == 0) continue;
      std::printf("%-12s %8ld", object.c_str(), s.rows);
      for (const auto& c : contact_sums) std::printf(" %16.3f", s.sum.at(c.name) / static_cast<double>(s.rows));
      for (const auto& c : contact_sums) std::printf(" %16.2f", s.max.at(c.name));
      std::printf("\n");
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
