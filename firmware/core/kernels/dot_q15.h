// Matrix and activation kernels of the q15 core (docs/architecture.md §6): the hot
// loops of HadynetNet's forward step (the LSTM gates, encoder, decoder, the
// gate activations) and of the stabiliser's backward pass, behind one
// interface whose implementation the build chooses:
//   kernels/reference/dot_q15.cc  plain loops over fixed_point.h and
//                                 activation.h (host builds)
//   kernels/cortex_m4/dot_q15.cc  Cortex-M4 DSP instructions (Cortex-M4 builds)
// Both compute the same exact integer results, so every output is
// bit-identical on every target (test/boards/ checks the DSP kernels against
// fixed_point.h and activation.h in QEMU). No core header says #ifdef:
// firmware/CMakeLists.txt picks the file.
//
// Sums are exact in int64: |int16 * int16| <= 2^30 and fewer than 2^16 terms
// (plus an int32 bias, shifted by at most 31) stay far below 2^63, in any
// order. rows, cols >= 0.
#ifndef HADYNET_FIRMWARE_CORE_KERNELS_DOT_Q15_H_
#define HADYNET_FIRMWARE_CORE_KERNELS_DOT_Q15_H_

#include <cstdint>

namespace hadynet::kernels {

// ---------------------------------------------------------------------------
// Packed matrices (the forward kernel's storage order)
// ---------------------------------------------------------------------------

// An int16 Rows x Cols matrix with its rows in pairs and its columns in
// chunks of eight: element (r, c) is data[packed_index(kCols, r, c)], i.e.
// row pair r / 2, chunk c / 8, then the eight columns of the pair's first
// row, then those of its second. Cols is padded to kCols (a multiple of 8)
// and an odd row count to an even one, with zeros. Built at compile time
// (pack_matrix) from a generated row-major matrix: the kernel then reads each
// eight columns of x once for two rows.
template <int Rows, int Cols>
struct PackedMatrix {
  static constexpr int kRows = Rows;
  static constexpr int kCols = (Cols + 7) / 8 * 8;
  static constexpr int kRowPairs = (Rows + 1) / 2;
  std::int16_t data[kRowPairs * 2 * kCols];
};

constexpr int packed_index(int padded_cols, int r, int c) noexcept {
  return (r / 2) * 2 * padded_cols + (c / 8) * 16 + (r % 2) * 8 + c % 8;
}

template <int Rows, int Cols>
constexpr PackedMatrix<Rows, Cols> pack_matrix(const std::int16_t (&w)[Rows][Cols]) noexcept {
  PackedMatrix<Rows, Cols> p{};
  for (int r = 0; r < Rows; ++r)
    for (int c = 0; c < Cols; ++c) p.data[packed_index(p.kCols, r, c)] = w[r][c];
  return p;
}

// ---------------------------------------------------------------------------
// Forward: requantised matrix-vector products
// ---------------------------------------------------------------------------

// One term of matvec_requantize_q15: the product W x of a packed matrix and
// an int16 vector, multiplied by 2^shift in the sum.
struct MatvecTerm {
  const std::int16_t* w = nullptr;  // PackedMatrix::data
  int cols = 0;                     // PackedMatrix::kCols (a multiple of 8, required); 0: the term is absent
  const std::int16_t* x = nullptr;  // cols elements (beyond the real columns: any values, they meet zeros)
  int shift = 0;                    // 0..31
};

// For r < rows (both terms' matrices have at least `rows` rows):
//   out[r] = fixed::requantize(bias[r] + (A_r . x_a) * 2^a.shift + (B_r . x_b) * 2^b.shift)
// where requantize divides the exact int64 sum by 2^out_shift, rounding half
// away from zero (fixed::rounding_shift_right), and saturates to int16
// (fixed::saturate_i16): one output of fixed::matvec, with up to two
// products summed before the single rounding (the LSTM gates:
// W_ih [u;p] + W_hh h). 0 <= out_shift <= 62; the caller's formats keep the
// exact sum within +-2^62.
void matvec_requantize_q15(const MatvecTerm& a, const MatvecTerm& b, const std::int32_t* bias, int rows,
                           int out_shift, std::int16_t* out) noexcept;

// v[i] = fixed::sigmoid_q15(v[i]) / fixed::tanh_q15(v[i]) for i < n, in place
// (Q3.12 in, Q0.15 out; activation.h).
void sigmoid_q15_block(std::int16_t* v, int n) noexcept;
void tanh_q15_block(std::int16_t* v, int n) noexcept;

// ---------------------------------------------------------------------------
// Backward: products with gradients
// ---------------------------------------------------------------------------

// acc[c] = sum_{r < rows} W(r, c) * g[r] for c < cols, W a packed matrix
// (`w` = PackedMatrix::data, `padded_cols` = its kCols) and g int16: W^T g
// from the forward kernel's own storage, so a model keeps one copy of each
// matrix (the model image's flash budget, docs/model-update.md). The
// gradients arrive as block floating point (numerics.h, grad_block_q15):
// int16 mantissas and one exponent the caller applies to the sums. g holds
// rows + rows % 2 entries: an odd count's last pair reads one more, which
// meets the packed matrix's zero padding row (any value).
void dot_cols_packed_q15(const std::int16_t* w, int padded_cols, int rows, const std::int16_t* g, int cols,
                         std::int64_t* acc) noexcept;

}  // namespace hadynet::kernels

#endif  // HADYNET_FIRMWARE_CORE_KERNELS_DOT_Q15_H_
