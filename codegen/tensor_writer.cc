#include "codegen/tensor_writer.h"

#include <algorithm>
#include <limits>

namespace hadynet::codegen {

std::int64_t Quantiser::operator()(double real, const std::string& where) {
  const std::int64_t q = to_fixed(real, frac);
  const std::int64_t lo = bias ? std::numeric_limits<std::int32_t>::min() : -32768;
  const std::int64_t hi = bias ? std::numeric_limits<std::int32_t>::max() : 32767;
  if (q < lo || q > hi) {
    reject(what + where + " = " + num(real) + " overflows " + (bias ? "int32" : "int16") +
           " in Q" + std::to_string(frac) +
           (bias ? " (its accumulator format): the weights or inputs need fewer fraction bits"
                 : ""));
  }
  max_error = std::max(max_error, std::abs(std::ldexp(static_cast<double>(q), -frac) - real));
  return q;
}

std::string index_text(Eigen::Index r, Eigen::Index c) {
  return "[" + std::to_string(r) + "]" + (c >= 0 ? "[" + std::to_string(c) + "]" : "");
}

}  // namespace hadynet::codegen
