// The quantisation step of codegen: a tensor's real values as literals in
// the header's numeric (q15: rounded into Q(frac) of an int16, or of an
// int32 for a bias, with the largest error reported; f32: float literals).
// Rejects (UnsupportedModel) a value that does not fit its format.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "codegen/formats.h"
#include "codegen/header_text.h"
#include "codegen/unsupported_model.h"
#include "firmware/core/model_contract.h"

namespace hadynet::codegen {

// Quantises real values into Q(frac) of an int16 (value) or int32 (bias),
// tracking the largest error.
struct Quantiser {
  int frac;
  bool bias;             // int32 instead of int16
  std::string what;      // tensor name, for errors and the report
  double max_error = 0;  // real units

  std::int64_t operator()(double real, const std::string& where);
};

// "[r]" or "[r][c]".
std::string index_text(Eigen::Index r, Eigen::Index c = -1);

// Values of a tensor as literals in the header's numeric: q15 quantised to
// Q(frac) (int32 when `bias`), f32 as float. `get(r, c)` is the real value (a
// float tensor's value widened, or a double statistic).
struct TensorWriter {
  firmware::Numeric numeric;
  std::vector<std::string> report;  // quantisation error lines

  template <class Get>
  std::vector<std::vector<std::string>> rows(const std::string& name, Eigen::Index n_rows,
                                             Eigen::Index n_cols, int frac, bool bias, Get get) {
    Quantiser q{frac, bias, name, 0.0};
    std::vector<std::vector<std::string>> out(static_cast<std::size_t>(n_rows));
    for (Eigen::Index r = 0; r < n_rows; ++r) {
      for (Eigen::Index c = 0; c < n_cols; ++c) {
        const double v = get(r, c);
        if (numeric == firmware::Numeric::kQ15) {
          out[static_cast<std::size_t>(r)].push_back(
              std::to_string(q(v, n_cols == 1 ? index_text(r) : index_text(r, c))));
        } else {
          out[static_cast<std::size_t>(r)].push_back(float_literal(static_cast<float>(v)));
        }
      }
    }
    if (numeric == firmware::Numeric::kQ15) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "//   %-16s Q%-2d  %.3g (%.3f LSB)", name.c_str(), frac,
                    q.max_error, std::ldexp(q.max_error, frac));
      report.push_back(buf);
    }
    return out;
  }
  template <class Get>
  std::vector<std::string> vector(const std::string& name, Eigen::Index n, int frac, bool bias,
                                  Get get) {
    std::vector<std::string> flat;
    for (auto& row : rows(name, n, 1, frac, bias, [&](Eigen::Index r, Eigen::Index) { return get(r); }))
      flat.push_back(row.front());
    return flat;
  }
};

}  // namespace hadynet::codegen
