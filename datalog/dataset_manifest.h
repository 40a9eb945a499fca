// DatasetManifest: the manifest.json of a dataset folder (docs/plant.md,
// "Datasets"): which logs the folder holds, their split and row counts.
// Reading is strict and bounded: every malformed manifest is a LogError that
// names the manifest file and the JSON field (logs[3].split), never a JSON
// library's exception; nothing partly read is returned.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "datalog/log_error.h"

namespace hadynet::datalog {

inline constexpr std::string_view kDatasetFormat = "hadynet-dataset";
inline constexpr int kDatasetFormatVersion = 1;
// Bytes of a manifest (the paper preset's 50 logs take about 12 KiB).
inline constexpr std::size_t kMaxManifestBytes = std::size_t{16} << 20;
// Logs one manifest may list.
inline constexpr std::size_t kMaxManifestLogs = 100000;

struct DatasetManifestEntry {
  std::filesystem::path file;        // relative to the dataset folder, no '..'
  std::string split;                 // "train", "test", ...; "?" when not given
  std::optional<std::size_t> rows;   // data rows the log must have, when given
};

struct DatasetManifest {
  std::vector<DatasetManifestEntry> logs;
};

// Parses manifest text; `file_for_errors` labels errors. Required: an object
// with "format": "hadynet-dataset" and a "logs" array of objects, each with a
// relative "file" string; optional: "format_version" (1), per log "split"
// (string) and "rows" (a whole number, at most 2^53). Other keys are kept by
// the writer for people and ignored here.
DatasetManifest parse_dataset_manifest(std::string_view text, const std::string& file_for_errors);

// Reads at most kMaxManifestBytes from `path` and parses it.
DatasetManifest read_dataset_manifest(const std::filesystem::path& path);

}  // namespace hadynet::datalog
