// The text of a generated header (codegen.h): literals that read back as
// exactly the value they stand for, comments that cannot break the code,
// lists wrapped within kWidth columns, and the emitter of `struct Model`'s
// static constexpr members. Pure string work; nothing here knows the model.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace hadynet::codegen {

// Generated lines stay within this many columns.
inline constexpr std::size_t kWidth = 100;

// A number for messages and comments ("%.4g").
std::string num(double v);
// The shortest "%.Ng" text that reads back as exactly v (options in the
// "Regenerate with" comment).
std::string exact_num(double v);

// A float literal ("1.0f", "-2.5e-05f") that reads back as exactly `v`;
// throws UnsupportedModel if `v` is not finite.
std::string float_literal(float v);
// A C++ string literal; quotes, backslashes and bytes outside printable ASCII
// as escapes (octal, three digits, so no following character can extend them).
std::string string_literal(const std::string& s);
// Text safe inside a // comment: no line breaks, no line-continuing backslash.
std::string comment_text(const std::string& s);
// `text` as // comment lines within kWidth columns, broken at spaces; the
// first line starts with `prefix`, the others with `continuation`.
std::string comment_lines(const std::string& prefix, const std::string& text, const std::string& continuation);
// Items separated by ", ", wrapped before kWidth columns; the first item
// starts at column `first_col`, continuation lines at `indent`.
std::string wrapped(const std::vector<std::string>& items, std::size_t first_col, std::size_t indent);

// Float literals of v; of 1 / stds computed in double and rounded once; string literals.
std::vector<std::string> float_items(const Eigen::VectorXd& v);
std::vector<std::string> inv_items(const Eigen::VectorXd& stds);
std::vector<std::string> string_items(const std::vector<std::string>& v);

// Appends lines of the header; members are written inside `struct Model`.
// Every member's literals are also kept by name ("kXMean", without the
// declarator's bounds; arrays flattened row by row): what the model image
// writer reads (codegen/model_image.h) and the shape id hashes.
struct Emitter {
  std::string out;
  std::map<std::string, std::vector<std::string>> literals;

  void line(const std::string& s = "");
  // static constexpr TYPE NAME = VALUE;  // COMMENT
  void member(const std::string& type, const std::string& name, const std::string& value,
              const std::string& comment = "");
  // A one-dimensional array, DECL e.g. "kXMean[kX]".
  void array1(const std::string& type, const std::string& decl, const std::vector<std::string>& items);
  // A two-dimensional array, one row per line group.
  void array2(const std::string& type, const std::string& decl, const std::vector<std::vector<std::string>>& rows);
};

}  // namespace hadynet::codegen
