#include "datalog/log_reader.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <optional>
#include <system_error>
#include <unordered_map>

#include "datalog/log_limits.h"
#include "datalog/log_rules.h"

namespace hadynet::datalog {
namespace {

constexpr std::size_t kNotFound = std::string_view::npos;

// ---- column names ----

struct ColumnName {
  enum class Kind { time, channel, aux, invalid };
  Kind kind = Kind::invalid;
  std::string_view prefix;  // channel: the [a-z]+ part
  std::size_t index = 0;    // channel: the decimal part
};

bool is_lower(char c) { return c >= 'a' && c <= 'z'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

// 't' | [a-z]+ (0 | [1-9][0-9]*) | 'aux_' followed by one or more bytes that
// are not ',', space or an ASCII control character.
ColumnName classify(std::string_view name) {
  ColumnName out;
  if (name == "t") {
    out.kind = ColumnName::Kind::time;
    return out;
  }
  constexpr std::string_view kAux = "aux_";
  if (name.starts_with(kAux)) {
    const std::string_view rest = name.substr(kAux.size());
    if (rest.empty()) return out;
    for (char c : rest) {
      const auto byte = static_cast<unsigned char>(c);
      if (c == ',' || byte <= 0x20u || byte == 0x7Fu) return out;
    }
    out.kind = ColumnName::Kind::aux;
    return out;
  }
  std::size_t split = 0;
  while (split < name.size() && is_lower(name[split])) ++split;
  const std::string_view prefix = name.substr(0, split);
  const std::string_view digits = name.substr(split);
  if (prefix.empty() || digits.empty()) return out;
  for (char c : digits) {
    if (!is_digit(c)) return out;
  }
  if (digits.size() > 1 && digits.front() == '0') return out;
  std::size_t index = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), index);
  if (ec != std::errc() || end != digits.data() + digits.size()) {
    index = static_cast<std::size_t>(-1);  // absurdly large: reported as out of order
  }
  out.kind = ColumnName::Kind::channel;
  out.prefix = prefix;
  out.index = index;
  return out;
}

// ---- text checks ----

std::size_t count_newlines(std::string_view text) {
  std::size_t n = 0;
  for (char c : text) n += c == '\n' ? 1 : 0;
  return n;
}

std::size_t count_commas(std::string_view text) {
  std::size_t n = 0;
  for (char c : text) n += c == ',' ? 1 : 0;
  return n;
}

// Iterates the lines of a text that ends with '\n'; line numbers are 1-based.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : text_(text), end_(text_.find('\n')) {}
  bool done() const { return pos_ >= text_.size(); }
  // The current line without its '\n'. Precondition: !done().
  std::string_view peek() const { return text_.substr(pos_, end_ - pos_); }
  // Line number of peek().
  std::size_t number() const { return number_; }
  // Byte offset of peek() in the text.
  std::size_t offset() const { return pos_; }
  void advance() {
    pos_ = end_ + 1;
    end_ = text_.find('\n', pos_);
    ++number_;
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t end_;
  std::size_t number_ = 1;
};

// ---- the parts of the file ----

// "# key: value" or "# key:" (empty value). The value is everything after
// ": ", kept verbatim.
void parse_metadata_line(std::string_view line, std::size_t line_no, const std::string& file,
                         LogMetadata& metadata) {
  const auto malformed = [&]() {
    return LogError(file, line_no, 0, "",
                    "malformed metadata line: expected '# key: value', got " + rules::quoted(line));
  };
  if (!line.starts_with("# ")) throw malformed();
  const std::size_t colon = line.find(':');
  if (colon == kNotFound) throw malformed();
  const std::string_view key = line.substr(2, colon - 2);
  rules::check_metadata_key(key, file, line_no);
  std::string_view value = line.substr(colon + 1);
  if (!value.empty()) {
    if (value.front() != ' ') throw malformed();
    value.remove_prefix(1);
  }
  if (const auto first = metadata.position(key)) {
    throw LogError(file, line_no, 0, "",
                   "duplicate metadata key " + rules::quoted(key) + " (first on line " +
                       std::to_string(*first + 1) + ")");
  }
  metadata.set(key, std::string(value));
}

std::vector<std::string> split_header(std::string_view line) {
  std::vector<std::string> names;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    names.emplace_back(line.substr(start, comma == kNotFound ? kNotFound : comma - start));
    if (comma == kNotFound) break;
    start = comma + 1;
  }
  return names;
}

// Appends the numbers of one data row to table.values.
void parse_data_row(std::string_view line, std::size_t line_no, const std::string& file,
                    LogTable& table) {
  const std::size_t expected = table.columns.size();
  std::size_t field = 0;  // 0-based index of the field being parsed
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::string_view text =
        line.substr(start, comma == kNotFound ? kNotFound : comma - start);
    if (field < expected) {
      const auto value = rules::parse_finite_number(text);
      if (!value) {
        throw LogError(file, line_no, field + 1, table.columns[field],
                       text.empty() ? std::string("expected a finite number, got an empty field")
                                    : "expected a finite number, got " + rules::quoted(text));
      }
      table.values.push_back(*value);
    }
    ++field;
    if (comma == kNotFound) break;
    start = comma + 1;
  }
  if (field != expected) {
    throw LogError(file, line_no, 0, "",
                   "expected " + std::to_string(expected) + " fields (one per header column), got " +
                       std::to_string(field));
  }
}

}  // namespace

ChannelLayout channel_layout(const LogTable& table, const std::string& file_for_errors) {
  const std::string& file = file_for_errors;
  const std::size_t line = rules::header_line(table);
  constexpr std::string_view kRules =
      "expected 't', '<prefix><index>' (prefix of a-z, index 0, 1, ... without leading zeros, "
      "e.g. 'l0') or 'aux_<name>'";

  ChannelLayout layout;
  std::optional<std::size_t> time_column;
  std::vector<ChannelGroup> groups;  // numbered groups in order of first appearance
  std::unordered_map<std::string_view, std::size_t> column_of_name;
  std::unordered_map<std::string_view, std::size_t> group_of_prefix;

  for (std::size_t i = 0; i < table.columns.size(); ++i) {
    const std::string& name = table.columns[i];
    const std::size_t column = i + 1;
    if (name.empty()) {
      throw LogError(file, line, column, "", "empty column name; " + std::string(kRules));
    }
    const ColumnName parsed = classify(name);
    if (parsed.kind == ColumnName::Kind::invalid) {
      throw LogError(file, line, column, name, "name fits no rule; " + std::string(kRules));
    }
    if (const auto [it, inserted] = column_of_name.emplace(name, column); !inserted) {
      throw LogError(file, line, column, name,
                     "duplicate column name (first at column " + std::to_string(it->second) + ")");
    }
    switch (parsed.kind) {
      case ColumnName::Kind::time:
        time_column = i;
        break;
      case ColumnName::Kind::aux:
        if (!layout.aux) layout.aux = ChannelGroup{"aux_", {}};
        layout.aux->columns.push_back(i);
        break;
      case ColumnName::Kind::channel: {
        const auto [it, inserted] = group_of_prefix.emplace(parsed.prefix, groups.size());
        if (inserted) groups.push_back(ChannelGroup{std::string(parsed.prefix), {}});
        ChannelGroup& group = groups[it->second];
        const std::size_t next = group.columns.size();
        if (parsed.index != next) {
          throw LogError(file, line, column, name,
                         "channel index out of order in group '" + group.prefix + "': expected '" +
                             group.prefix + std::to_string(next) + "'");
        }
        group.columns.push_back(i);
        break;
      }
      case ColumnName::Kind::invalid:
        break;
    }
  }

  if (!time_column) throw LogError(file, line, 0, "", "missing time column 't'");
  layout.time_column = *time_column;
  for (ChannelGroup& group : groups) {
    if (group.prefix == "u") {
      layout.command = std::move(group);
    } else {
      layout.observed.push_back(std::move(group));
    }
  }
  if (layout.observed.empty()) {
    throw LogError(file, line, 0, "",
                   "no observed channel group; expected at least one numbered group other than "
                   "'u' (e.g. 'l0')");
  }
  return layout;
}

void check_magnitudes(const LogTable& table, std::span<const std::size_t> columns, double limit,
                      const std::string& file_for_errors, const std::string& reason) {
  const std::size_t first_data_line = rules::header_line(table) + 1;
  for (std::size_t r = 0; r < table.rows(); ++r) {
    for (const std::size_t c : columns) {
      const double v = table.at(r, c);
      if (!(std::fabs(v) <= limit)) {
        throw LogError(file_for_errors, first_data_line + r, c + 1, table.columns[c],
                       "value " + rules::format_number(v) + " is beyond +-" +
                           rules::format_number(limit) + ": " + reason);
      }
    }
  }
}

double log_dt_s(const LogTable& table, const std::string& file_for_errors) {
  return rules::check_dt_s(table.metadata, file_for_errors);
}

LogTable parse_log(std::string_view text, const std::string& file_for_errors) {
  const std::string& file = file_for_errors;
  if (text.empty()) {
    throw LogError(file, 0, 0, "",
                   "empty file; expected '# key: value' metadata lines, a header row and data rows");
  }
  if (text.size() > kMaxLogBytes) {
    throw LogError(file, 0, 0, "",
                   "file of " + std::to_string(text.size()) + " bytes; a log may hold at most " +
                       std::to_string(kMaxLogBytes) + " bytes (docs/input-limits.md)");
  }
  if (text.back() != '\n') {
    // Old Mac line ends (CR alone) leave no LF after the last line break.
    const std::size_t last_lf = text.rfind('\n');
    const std::size_t tail = last_lf == kNotFound ? 0 : last_lf + 1;
    if (text.find('\r', tail) != kNotFound) {
      throw LogError(file, count_newlines(text) + 1, 0, "",
                     "carriage return (CR) line ends without LF; expected lines ending in LF only");
    }
    throw LogError(file, count_newlines(text) + 1, 0, "",
                   "truncated last line (no newline at end of file)");
  }
  if (text.starts_with("\xEF\xBB\xBF")) {
    throw LogError(file, 1, 0, "", "UTF-8 byte order mark at the start of the file; expected none");
  }
  if (const std::size_t bad = rules::first_invalid_utf8(text); bad != kNotFound) {
    throw LogError(file, count_newlines(text.substr(0, bad)) + 1, 0, "",
                   rules::invalid_utf8_message(text, bad));
  }

  LogTable table;
  LineCursor cursor(text);
  const auto check_no_cr = [&](std::string_view line) {
    if (line.find('\r') != kNotFound) {
      throw LogError(file, cursor.number(), 0, "",
                     "carriage return in line (CRLF line end?); expected lines ending in LF only");
    }
  };

  // Metadata: every leading line that starts with '#'.
  while (!cursor.done() && cursor.peek().starts_with('#')) {
    check_no_cr(cursor.peek());
    if (table.metadata.entries().size() == kMaxMetadataLines) {
      throw LogError(file, cursor.number(), 0, "",
                     "more than " + std::to_string(kMaxMetadataLines) +
                         " metadata lines; a log may hold at most that many (docs/input-limits.md)");
    }
    parse_metadata_line(cursor.peek(), cursor.number(), file, table.metadata);
    cursor.advance();
  }
  const double dt_s = rules::check_required_metadata(table.metadata, file);

  // Header.
  if (cursor.done()) {
    throw LogError(file, 0, 0, "",
                   "no header row after the metadata; expected a line of comma-separated column "
                   "names");
  }
  const std::string_view header = cursor.peek();
  check_no_cr(header);
  if (header.empty()) {
    throw LogError(file, cursor.number(), 0, "",
                   "empty header row; expected comma-separated column names");
  }
  const std::size_t header_line = cursor.number();
  if (const std::size_t names = count_commas(header) + 1; names > kMaxLogColumns) {
    throw LogError(file, header_line, 0, "",
                   "header of " + std::to_string(names) + " columns; a log may hold at most " +
                       std::to_string(kMaxLogColumns) + " (docs/input-limits.md)");
  }
  table.columns = split_header(header);
  const ChannelLayout layout = channel_layout(table, file);
  cursor.advance();

  // Data rows.
  const std::size_t time_field = layout.time_column + 1;
  double previous_t_s = 0.0;
  std::size_t rows = 0;
  // Every field takes at least two bytes of text ("0,"), which bounds the
  // values of a valid file: a wrong header never makes the reservation large.
  const std::string_view data = text.substr(cursor.offset());
  table.values.reserve(std::min(count_newlines(data) * table.columns.size(), data.size() / 2 + 1));
  while (!cursor.done()) {
    const std::string_view line = cursor.peek();
    const std::size_t line_no = cursor.number();
    check_no_cr(line);
    if (line.empty()) {
      throw LogError(file, line_no, 0, "",
                     "blank line inside the data; expected a data row of " +
                         std::to_string(table.columns.size()) + " numbers");
    }
    if (line.starts_with('#')) {
      throw LogError(file, line_no, 0, "",
                     "metadata line after the header; '# key: value' lines must all precede the "
                     "header row");
    }
    parse_data_row(line, line_no, file, table);
    const double t_s = table.at(rows, layout.time_column);
    if (rows > 0) rules::check_time_step(previous_t_s, t_s, dt_s, file, line_no, time_field);
    previous_t_s = t_s;
    ++rows;
    cursor.advance();
  }
  if (rows == 0) {
    throw LogError(file, 0, 0, "",
                   "no data rows after the header (line " + std::to_string(header_line) +
                       "); expected at least one");
  }
  return table;
}

LogTable read_log(const std::filesystem::path& path) {
  const std::string file = path.string();
  const auto fail = [&](int error) {
    return LogError(file, 0, 0, "",
                    "cannot read log file: " + std::generic_category().message(error));
  };
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw fail(errno);
  // Reads at most kMaxLogBytes + 1 bytes: whatever the file is (a device such
  // as /dev/zero, a pipe, a huge file), the reader stops and parse_log names
  // the size.
  std::string text;
  constexpr std::size_t kChunk = std::size_t{1} << 16;
  while (text.size() <= kMaxLogBytes) {
    const std::size_t used = text.size();
    text.resize(used + kChunk);
    const ssize_t n = ::read(fd, text.data() + used, kChunk);
    const int error = errno;
    text.resize(used + (n > 0 ? static_cast<std::size_t>(n) : 0));
    if (n == 0) break;
    if (n < 0) {
      if (error == EINTR) continue;
      ::close(fd);
      throw fail(error);
    }
  }
  ::close(fd);
  if (text.size() > kMaxLogBytes) {
    throw LogError(file, 0, 0, "",
                   "more than " + std::to_string(kMaxLogBytes) +
                       " bytes; a log may hold at most that many (docs/input-limits.md)");
  }
  return parse_log(text, file);
}

}  // namespace hadynet::datalog
