// kernels/dot_q15.h for a build without optimised kernels (every build but
// the Cortex-M4's): the reference kernels as they are.
#include "firmware/core/kernels/dot_q15.h"

#include "firmware/core/kernels/reference/dot_q15_reference.h"

namespace hadynet::kernels {

void matvec_requantize_q15(const MatvecTerm& a, const MatvecTerm& b, const std::int32_t* bias, int rows,
                           int out_shift, std::int16_t* out) noexcept {
  reference::matvec_requantize_q15(a, b, bias, rows, out_shift, out);
}

void sigmoid_q15_block(std::int16_t* v, int n) noexcept { reference::sigmoid_q15_block(v, n); }

void tanh_q15_block(std::int16_t* v, int n) noexcept { reference::tanh_q15_block(v, n); }

void dot_cols_packed_q15(const std::int16_t* w, int padded_cols, int rows, const std::int16_t* g, int cols,
                         std::int64_t* acc) noexcept {
  reference::dot_cols_packed_q15(w, padded_cols, rows, g, cols, acc);
}

}  // namespace hadynet::kernels
