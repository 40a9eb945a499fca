// The reference kernels: kernels/dot_q15.h's contracts in plain C++ (the
// specification of each function is there), under their own names, so that
// an optimised implementation can call them for the shapes its fast paths do
// not take (TensorFlow Lite Micro's pattern) and a build without one uses
// them as they are (reference/dot_q15.cc). Compiled into every build's
// kernel library.
#ifndef HADYNET_FIRMWARE_CORE_KERNELS_REFERENCE_DOT_Q15_REFERENCE_H_
#define HADYNET_FIRMWARE_CORE_KERNELS_REFERENCE_DOT_Q15_REFERENCE_H_

#include <cstdint>

#include "firmware/core/kernels/dot_q15.h"

namespace hadynet::kernels::reference {

void matvec_requantize_q15(const MatvecTerm& a, const MatvecTerm& b, const std::int32_t* bias, int rows,
                           int out_shift, std::int16_t* out) noexcept;
void sigmoid_q15_block(std::int16_t* v, int n) noexcept;
void tanh_q15_block(std::int16_t* v, int n) noexcept;
void dot_cols_packed_q15(const std::int16_t* w, int padded_cols, int rows, const std::int16_t* g, int cols,
                         std::int64_t* acc) noexcept;

}  // namespace hadynet::kernels::reference

#endif  // HADYNET_FIRMWARE_CORE_KERNELS_REFERENCE_DOT_Q15_REFERENCE_H_
