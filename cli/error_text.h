// The text a command prints for an exception that ended it. Library errors
// (LogError, ModelFileError, LinkError, ...) already name the file and field;
// the few exceptions of the C++ library whose own text means nothing to a
// user are worded here, so no "std::bad_alloc" or "stod" reaches stderr alone.
#pragma once

#include <exception>
#include <new>
#include <string>

namespace hadynet::cli {

inline std::string error_text(const std::exception& e) {
  if (dynamic_cast<const std::bad_alloc*>(&e) != nullptr) {
    return "out of memory: the inputs need more memory than this machine has (the input limits are in "
           "docs/input-limits.md)";
  }
  const std::string what = e.what();
  if (what.rfind("sto", 0) == 0 && what.size() <= 6) {  // std::stoi, stod, stof, ... with no context
    return "a number in the input is out of range or not a number (" + what + ")";
  }
  return what;
}

}  // namespace hadynet::cli
