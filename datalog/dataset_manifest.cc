#include "datalog/dataset_manifest.h"

#include <cerrno>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <system_error>

#include "datalog/log_rules.h"

namespace hadynet::datalog {
namespace {

using json = nlohmann::json;

[[noreturn]] void fail(const std::string& file, const std::string& message) {
  throw LogError(file, 0, 0, "", message);
}

// JSON type names as a person reads them.
std::string type_of(const json& j) {
  switch (j.type()) {
    case json::value_t::null: return "null";
    case json::value_t::object: return "an object";
    case json::value_t::array: return "an array";
    case json::value_t::string: return "a string";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned: return "a whole number";
    case json::value_t::number_float: return "a number with a fraction or exponent";
    default: return "another JSON type";
  }
}

[[noreturn]] void wrong_type(const std::string& file, const std::string& field, const json& j,
                             const std::string& expected) {
  fail(file, "field '" + field + "': expected " + expected + ", got " + type_of(j));
}

std::string string_field(const std::string& file, const json& object, const char* key,
                         const std::string& field) {
  const json& j = object.at(key);
  if (!j.is_string()) wrong_type(file, field, j, "a string");
  return j.get<std::string>();
}

// The log's path inside the dataset folder: relative, and never above it.
std::filesystem::path relative_file(const std::string& file, const std::string& text,
                                    const std::string& field) {
  const std::filesystem::path p(text);
  if (text.empty() || p.is_absolute()) {
    fail(file, "field '" + field + "': expected a path relative to the dataset folder, got " +
                   rules::quoted(text));
  }
  for (const auto& part : p) {
    if (part == "..") {
      fail(file, "field '" + field + "': the path " + rules::quoted(text) +
                     " leaves the dataset folder ('..')");
    }
  }
  return p;
}

}  // namespace

DatasetManifest parse_dataset_manifest(std::string_view text, const std::string& file) {
  if (text.size() > kMaxManifestBytes) {
    fail(file, "manifest of " + std::to_string(text.size()) + " bytes; at most " +
                   std::to_string(kMaxManifestBytes) + " are read");
  }
  json root;
  try {
    root = json::parse(text);
  } catch (const json::parse_error& e) {
    fail(file, "byte " + std::to_string(e.byte) + ": not valid JSON");
  } catch (const json::exception& e) {
    // e.g. out_of_range 406: a number beyond double's range such as 1e400.
    fail(file, std::string("not readable JSON: ") +
                   (e.id == 406 ? "a number beyond the range of a double" : "malformed value"));
  }
  if (!root.is_object()) wrong_type(file, "(top level)", root, "an object");
  if (!root.contains("format")) fail(file, "no field 'format'; expected \"hadynet-dataset\"");
  if (string_field(file, root, "format", "format") != kDatasetFormat) {
    fail(file, "field 'format': expected \"hadynet-dataset\", got " +
                   rules::quoted(root.at("format").get<std::string>()));
  }
  if (root.contains("format_version")) {
    const json& v = root.at("format_version");
    if (!v.is_number_integer() || v.get<long long>() != kDatasetFormatVersion) {
      fail(file, "field 'format_version': expected " + std::to_string(kDatasetFormatVersion) +
                     ", got " + (v.is_number_integer() ? v.dump() : type_of(v)));
    }
  }
  if (!root.contains("logs")) fail(file, "no field 'logs'; expected an array of logs");
  const json& logs = root.at("logs");
  if (!logs.is_array()) wrong_type(file, "logs", logs, "an array");
  if (logs.size() > kMaxManifestLogs) {
    fail(file, "field 'logs': " + std::to_string(logs.size()) + " logs; at most " +
                   std::to_string(kMaxManifestLogs) + " are read");
  }

  DatasetManifest manifest;
  manifest.logs.reserve(logs.size());
  for (std::size_t i = 0; i < logs.size(); ++i) {
    const std::string where = "logs[" + std::to_string(i) + "]";
    const json& log = logs[i];
    if (!log.is_object()) wrong_type(file, where, log, "an object");
    if (!log.contains("file")) fail(file, "field '" + where + "': no \"file\"");
    DatasetManifestEntry entry;
    entry.file = relative_file(file, string_field(file, log, "file", where + ".file"), where + ".file");
    entry.split = log.contains("split") ? string_field(file, log, "split", where + ".split") : "?";
    if (log.contains("rows")) {
      const json& rows = log.at("rows");
      constexpr unsigned long long kMaxRows = 1ull << 53;
      if (!rows.is_number_integer()) wrong_type(file, where + ".rows", rows, "a whole number >= 0");
      if (!rows.is_number_unsigned() && rows.get<long long>() < 0) {
        fail(file, "field '" + where + ".rows': expected a whole number >= 0, got " + rows.dump());
      }
      const unsigned long long n = rows.get<unsigned long long>();
      if (n > kMaxRows) {
        fail(file, "field '" + where + ".rows': " + rows.dump() + " is beyond 2^53");
      }
      entry.rows = static_cast<std::size_t>(n);
    }
    manifest.logs.push_back(std::move(entry));
  }
  return manifest;
}

DatasetManifest read_dataset_manifest(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!in) {
    fail(file, "cannot read the manifest: " + std::generic_category().message(errno));
  }
  std::string text;
  char buffer[1 << 16];
  while (text.size() <= kMaxManifestBytes) {
    const std::size_t n = std::fread(buffer, 1, sizeof buffer, in.get());
    text.append(buffer, n);
    if (n < sizeof buffer) break;
  }
  if (std::ferror(in.get())) fail(file, "cannot read the manifest: read error");
  return parse_dataset_manifest(text, file);
}

}  // namespace hadynet::datalog
