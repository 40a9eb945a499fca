// The reference kernels (dot_q15_reference.h): the plain exact sums, the
// requantisation of fixed_point.h and the activations of activation.h, in
// the obvious order. What optimised kernels are tested against, and what
// they call outside their fast paths; do not optimise it in place
// (docs/architecture.md §6).
#include "firmware/core/kernels/reference/dot_q15_reference.h"

#include <cstdint>

#include "firmware/core/activation.h"
#include "firmware/core/fixed_point.h"

namespace hadynet::kernels::reference {

namespace {

// Both rows of row pair p of a packed matrix times x, times 2^shift, added
// to sum[0], sum[1]. A pair's chunks of eight columns alternate between its
// two rows (packed_index). Sixteen exact int64 sums, one per row and column
// within a chunk, then their totals (exact, so the order does not matter;
// this order lets the host compiler vectorise it).
void add_pair(const MatvecTerm& t, int p, std::int64_t (&sum)[2]) noexcept {
  if (t.cols <= 0) return;
  const std::int16_t* chunk = t.w + packed_index(t.cols, 2 * p, 0);
  std::int64_t lanes[2][8] = {};
  for (int c = 0; c < t.cols; c += 8, chunk += 16) {
    for (int i = 0; i < 8; ++i) {
      lanes[0][i] = fixed::mac(lanes[0][i], chunk[i], t.x[c + i]);
      lanes[1][i] = fixed::mac(lanes[1][i], chunk[8 + i], t.x[c + i]);
    }
  }
  for (int row = 0; row < 2; ++row) {
    std::int64_t total = 0;
    for (const std::int64_t lane : lanes[row]) total += lane;
    sum[row] += total * (std::int64_t{1} << t.shift);
  }
}

}  // namespace

void matvec_requantize_q15(const MatvecTerm& a, const MatvecTerm& b, const std::int32_t* bias, int rows,
                           int out_shift, std::int16_t* out) noexcept {
  for (int r = 0; r < rows; r += 2) {
    // An odd last row is the first of a pair whose second is padding.
    std::int64_t sum[2] = {bias[r], r + 1 < rows ? bias[r + 1] : 0};
    add_pair(a, r / 2, sum);
    add_pair(b, r / 2, sum);
    out[r] = fixed::saturate_i16(fixed::rounding_shift_right(sum[0], out_shift));
    if (r + 1 < rows) out[r + 1] = fixed::saturate_i16(fixed::rounding_shift_right(sum[1], out_shift));
  }
}

void sigmoid_q15_block(std::int16_t* v, int n) noexcept {
  for (int i = 0; i < n; ++i) v[i] = fixed::sigmoid_q15(v[i]);
}

void tanh_q15_block(std::int16_t* v, int n) noexcept {
  for (int i = 0; i < n; ++i) v[i] = fixed::tanh_q15(v[i]);
}

void dot_cols_packed_q15(const std::int16_t* w, int padded_cols, int rows, const std::int16_t* g, int cols,
                         std::int64_t* acc) noexcept {
  for (int c = 0; c < cols; ++c) acc[c] = 0;
  for (int r = 0; r < rows; ++r) {
    const std::int64_t gr = g[r];
    for (int c = 0; c < cols; ++c) acc[c] += w[packed_index(padded_cols, r, c)] * gr;
  }
}

}  // namespace hadynet::kernels::reference
