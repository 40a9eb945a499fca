#include "codegen/header_text.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "codegen/unsupported_model.h"

namespace hadynet::codegen {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

std::string exact_num(double v) {
  char buf[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

// ("%.9g" round-trips every float.)
std::string float_literal(float v) {
  if (!std::isfinite(v)) reject("a value is not finite in float32");
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
  const float back = std::strtof(buf, nullptr);
  if (std::memcmp(&back, &v, sizeof v) != 0) {
    throw std::logic_error(std::string("codegen: float literal ") + buf + " does not round-trip");
  }
  std::string s = buf;
  if (s.find_first_of(".e") == std::string::npos) s += ".0";  // "1" -> "1.0f", "-0" -> "-0.0f"
  return s + "f";
}

std::string string_literal(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20 || c >= 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\%03o", static_cast<unsigned>(c));
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string comment_text(const std::string& s) {
  std::string out;
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    out += (c < 0x20 || c == 0x7f || c == '\\') ? '?' : ch;
  }
  return out;
}

std::string comment_lines(const std::string& prefix, const std::string& text,
                          const std::string& continuation) {
  std::string out, line = prefix;
  std::size_t start = 0;
  bool first_word = true;
  while (start < text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    start = end + 1;
    if (word.empty()) continue;
    if (!first_word && line.size() + 1 + word.size() > kWidth) {
      out += line + "\n";
      line = continuation + word;
    } else {
      line += (first_word ? "" : " ") + word;
    }
    first_word = false;
  }
  return out + line + "\n";
}

std::string wrapped(const std::vector<std::string>& items, std::size_t first_col,
                    std::size_t indent) {
  std::string s;
  std::size_t col = first_col;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string piece = items[i] + (i + 1 < items.size() ? "," : "");
    if (i > 0) {
      if (col + 1 + piece.size() > kWidth - 2) {  // room for a closing "};" or "},"
        s += '\n';
        s.append(indent, ' ');
        col = indent;
      } else {
        s += ' ';
        ++col;
      }
    }
    s += piece;
    col += piece.size();
  }
  return s;
}

std::vector<std::string> float_items(const Eigen::VectorXd& v) {
  std::vector<std::string> items;
  for (Eigen::Index i = 0; i < v.size(); ++i) items.push_back(float_literal(static_cast<float>(v(i))));
  return items;
}

std::vector<std::string> inv_items(const Eigen::VectorXd& stds) {
  std::vector<std::string> items;
  for (Eigen::Index i = 0; i < stds.size(); ++i)
    items.push_back(float_literal(static_cast<float>(1.0 / stds(i))));
  return items;
}

std::vector<std::string> string_items(const std::vector<std::string>& v) {
  std::vector<std::string> items;
  for (const std::string& s : v) items.push_back(string_literal(s));
  return items;
}

void Emitter::line(const std::string& s) {
  out += s;
  out += '\n';
}

namespace {
std::string member_name(const std::string& decl) { return decl.substr(0, decl.find('[')); }
}  // namespace

void Emitter::member(const std::string& type, const std::string& name, const std::string& value,
                     const std::string& comment) {
  literals[member_name(name)] = {value};
  line("  static constexpr " + type + " " + name + " = " + value + ";" + (comment.empty() ? "" : "  // " + comment));
}

void Emitter::array1(const std::string& type, const std::string& decl, const std::vector<std::string>& items) {
  literals[member_name(decl)] = items;
  line("  static constexpr " + type + " " + decl + " = {");
  line("      " + wrapped(items, 6, 6) + "};");
}

void Emitter::array2(const std::string& type, const std::string& decl,
                     const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::string>& flat = literals[member_name(decl)];
  flat.clear();
  for (const auto& row : rows) flat.insert(flat.end(), row.begin(), row.end());
  line("  static constexpr " + type + " " + decl + " = {");
  for (const auto& row : rows) line("      {" + wrapped(row, 7, 7) + "},");
  line("  };");
}

}  // namespace hadynet::codegen
