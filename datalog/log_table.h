// In-memory form of one HADYNET log (docs/log-format.md): metadata lines,
// a header of column names and a dense table of finite doubles, one row per
// control step. Channel groups (l, f, fc, th, u, aux_*) are derived from the
// column names, never from fixed counts, so logs of other robots load too.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

namespace hadynet::datalog {

// The only format version this reader and writer understand.
inline constexpr int kFormatVersion = 1;

// Ordered `# key: value` metadata lines. Keys are unique. Look-ups and
// inserts take constant time on average (a log of many keys reads in
// linear time).
class LogMetadata {
 public:
  std::optional<std::string> get(std::string_view key) const;
  // 0-based position of `key` in entries(), or nullopt.
  std::optional<std::size_t> position(std::string_view key) const;
  // Inserts or replaces; keeps the first insertion order.
  void set(std::string_view key, std::string value);
  const std::vector<std::pair<std::string, std::string>>& entries() const { return entries_; }

 private:
  // Heterogeneous look-up by string_view without a temporary string.
  struct KeyHash {
    using is_transparent = void;
    std::size_t operator()(std::string_view key) const noexcept {
      return std::hash<std::string_view>{}(key);
    }
  };
  std::vector<std::pair<std::string, std::string>> entries_;
  std::unordered_map<std::string, std::size_t, KeyHash, std::equal_to<>> position_;  // key -> index
};

// The unit a log's `units` metadata text gives `key` (a channel group's
// prefix or a channel: "N" for "fc" in "t=s fc=N"); empty when it gives none.
std::string declared_unit(std::string_view units_text, std::string_view key);

// One channel group: columns named <prefix>0 .. <prefix>N-1 (e.g. fc0..fc8),
// or, for auxiliary channels, every column whose name starts with "aux_".
struct ChannelGroup {
  std::string prefix;               // "l", "f", "fc", "th", "u", "aux_"
  std::vector<std::size_t> columns; // column indices into LogTable::columns, in channel order
};

// Column roles, derived from the header.
struct ChannelLayout {
  std::size_t time_column = 0;       // the "t" column
  std::vector<ChannelGroup> observed; // y groups in header order (every numbered group but "u")
  std::optional<ChannelGroup> command; // the "u" group (change of target per step)
  std::optional<ChannelGroup> aux;     // "aux_*" columns, not used as model inputs by default
};

struct LogTable {
  LogMetadata metadata;
  std::vector<std::string> columns;  // header, in file order
  std::vector<double> values;        // row-major, rows() x columns.size(), all finite

  std::size_t rows() const { return columns.empty() ? 0 : values.size() / columns.size(); }
  double at(std::size_t row, std::size_t col) const { return values[row * columns.size() + col]; }
  double& at(std::size_t row, std::size_t col) { return values[row * columns.size() + col]; }
  std::optional<std::size_t> column_index(std::string_view name) const;
  // Appends one row; `row.size()` must equal columns.size().
  void append_row(const std::vector<double>& row);
};

}  // namespace hadynet::datalog
