// The one error of codegen: the model (or the options) cannot be generated.
#pragma once

#include <stdexcept>
#include <string>

namespace hadynet::codegen {

// what() names the problem.
class UnsupportedModel : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws UnsupportedModel(message).
[[noreturn]] inline void reject(const std::string& message) { throw UnsupportedModel(message); }

}  // namespace hadynet::codegen
