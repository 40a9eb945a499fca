#include "datalog/log_rules.h"

#include <charconv>
#include <cmath>
#include <system_error>

#include "datalog/log_error.h"

namespace hadynet::datalog::rules {

void check_metadata_key(std::string_view key, const std::string& file, std::size_t line) {
  bool valid = !key.empty();
  for (char c : key) {
    valid = valid && ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_');
  }
  if (!valid) {
    throw LogError(file, line, 0, "",
                   "invalid metadata key " + quoted(key) + ": expected one or more of a-z, 0-9, '_'");
  }
}

namespace {

// Line of `key` in the file (1-based), or 0 when absent.
std::size_t line_of(const LogMetadata& metadata, std::string_view key) {
  const auto i = metadata.position(key);
  return i ? *i + 1 : 0;
}

[[noreturn]] void missing(const std::string& file, std::string_view key, std::string_view example) {
  throw LogError(file, 0, 0, "",
                 "missing required metadata line '# " + std::string(key) + ": ...' (e.g. '# " +
                     std::string(key) + ": " + std::string(example) + "')");
}

}  // namespace

double check_required_metadata(const LogMetadata& metadata, const std::string& file) {
  const auto format = metadata.get("format");
  if (!format) missing(file, "format", kFormatName);
  if (*format != kFormatName) {
    throw LogError(file, line_of(metadata, "format"), 0, "",
                   "metadata 'format': expected '" + std::string(kFormatName) + "', got " +
                       quoted(*format));
  }

  const auto version = metadata.get("format_version");
  if (!version) missing(file, "format_version", std::to_string(kFormatVersion));
  if (*version != std::to_string(kFormatVersion)) {
    throw LogError(file, line_of(metadata, "format_version"), 0, "",
                   "unsupported format_version " + quoted(*version) +
                       "; the supported format_version is " + std::to_string(kFormatVersion));
  }

  return check_dt_s(metadata, file);
}

double check_dt_s(const LogMetadata& metadata, const std::string& file) {
  const auto dt = metadata.get("dt_s");
  if (!dt) missing(file, "dt_s", "0.2");
  const auto dt_s = parse_finite_number(*dt);
  if (!dt_s || !(*dt_s >= kMinDtS && *dt_s <= kMaxDtS)) {
    throw LogError(file, line_of(metadata, "dt_s"), 0, "",
                   "metadata 'dt_s': expected a number of seconds from " + format_number(kMinDtS) +
                       " to " + format_number(kMaxDtS) + ", got " + quoted(*dt));
  }
  return *dt_s;
}

std::optional<double> parse_finite_number(std::string_view field) {
  double value = 0.0;
  const char* first = field.data();
  const char* last = first + field.size();
  const auto [end, ec] = std::from_chars(first, last, value, std::chars_format::general);
  if (ec != std::errc() || end != last || !std::isfinite(value)) return std::nullopt;
  return value;
}

void append_number(std::string& out, double value) {
  char buffer[32];  // the longest shortest-round-trip double is 24 characters
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  (void)ec;  // cannot fail: the buffer is large enough
  out.append(buffer, end);
}

std::string format_number(double value) {
  std::string out;
  append_number(out, value);
  return out;
}

void check_time_step(double t_prev_s, double t_s, double dt_s, const std::string& file,
                     std::size_t line, std::size_t column) {
  const double step_s = t_s - t_prev_s;
  if (!(step_s > 0.0)) {
    throw LogError(file, line, column, "t",
                   "time not strictly increasing: t = " + format_number(t_s) +
                       " s after t = " + format_number(t_prev_s) + " s on the previous line");
  }
  const double tolerance_s = time_step_tolerance_s(dt_s);
  if (std::fabs(step_s - dt_s) > tolerance_s) {
    // Derived values rounded for reading (0.4, not 0.39999999999999997).
    const auto rounded = [](double value, int digits) {
      char buffer[32];
      const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value,
                                           std::chars_format::general, digits);
      (void)ec;  // cannot fail: the buffer is large enough
      return std::string(buffer, end);
    };
    throw LogError(file, line, column, "t",
                   "irregular time step: t = " + format_number(t_s) + " s after t = " +
                       format_number(t_prev_s) + " s is a step of " + rounded(step_s, 9) +
                       " s, expected dt_s = " + format_number(dt_s) + " s (tolerance " +
                       rounded(tolerance_s, 6) + " s)");
  }
}

// Offset of the first byte that does not belong to a well-formed UTF-8
// sequence (no overlongs, no surrogates, <= U+10FFFF), or std::string_view::npos.
std::size_t first_invalid_utf8(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto b0 = static_cast<unsigned char>(text[i]);
    if (b0 < 0x80u) {
      ++i;
      continue;
    }
    std::size_t length = 0;
    unsigned char low = 0x80u;  // allowed range of the second byte
    unsigned char high = 0xBFu;
    if (b0 >= 0xC2u && b0 <= 0xDFu) {
      length = 2;
    } else if (b0 >= 0xE0u && b0 <= 0xEFu) {
      length = 3;
      if (b0 == 0xE0u) low = 0xA0u;   // overlong
      if (b0 == 0xEDu) high = 0x9Fu;  // surrogates
    } else if (b0 >= 0xF0u && b0 <= 0xF4u) {
      length = 4;
      if (b0 == 0xF0u) low = 0x90u;   // overlong
      if (b0 == 0xF4u) high = 0x8Fu;  // above U+10FFFF
    } else {
      return i;
    }
    if (i + length > text.size()) return i;
    for (std::size_t k = 1; k < length; ++k) {
      const auto b = static_cast<unsigned char>(text[i + k]);
      const unsigned char lo = k == 1 ? low : 0x80u;
      const unsigned char hi = k == 1 ? high : 0xBFu;
      if (b < lo || b > hi) return i;
    }
    i += length;
  }
  return std::string_view::npos;
}

std::string invalid_utf8_message(std::string_view text, std::size_t offset) {
  const std::size_t newline = offset == 0 ? std::string_view::npos : text.rfind('\n', offset - 1);
  const std::size_t line_start = newline == std::string_view::npos ? 0 : newline + 1;
  return "invalid UTF-8 at byte " + std::to_string(offset - line_start + 1) +
         " of the line; expected UTF-8 text";
}

std::string printable(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20u || byte == 0x7Fu) {
      out += "\\x";
      out += kHex[byte >> 4];
      out += kHex[byte & 0xFu];
    } else {
      out += c;
    }
  }
  return out;
}

std::string quoted(std::string_view text) {
  constexpr std::size_t kMaxShown = 40;
  std::string out(1, '\'');
  if (text.size() <= kMaxShown) {
    out += printable(text);
    out += '\'';
    return out;
  }
  std::size_t cut = kMaxShown;
  // Do not cut a UTF-8 sequence in half.
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0u) == 0x80u) --cut;
  out += printable(text.substr(0, cut));
  out += "...' (";
  out += std::to_string(text.size());
  out += " bytes)";
  return out;
}

}  // namespace hadynet::datalog::rules
