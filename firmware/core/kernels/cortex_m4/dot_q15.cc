// Cortex-M4 implementation of kernels/dot_q15.h with the DSP extension: the
// C++ side (shape checks, job blocks, the entry into the unrolled loops) of
// the assembly in dot_q15_m4.S, whose layout kernel_layout.h single-sources.
//
// The multiply-accumulate is SMLALD: the two int16 halves of one word of W
// times those of one word of x, both products added to a 64-bit
// accumulator, exactly (as fixed::dot). SMLAD would accumulate in 32 bits,
// and no 32-bit bound holds for arbitrary int16 data: a single SMLAD of
// (-32768)^2 + (-32768)^2 = 2^31 already overflows int32.
//
// matvec_requantize_q15: two rows at a time on packed matrices (rows in
// pairs, columns in chunks of eight, kernels/dot_q15.h): per eight columns
// one LDM of x (four words, eight int16) serves one LDM of each row and eight
// SMLALD: 11 instructions per 16 MACs. The column loops are fully unrolled
// and entered at the depth the column count needs (no loop counter: x, W,
// two accumulators and two pointers take all 14 registers). After the first
// term the accumulators are shifted by the difference of the two terms'
// shifts, the second term accumulates on top, then bias, rounding (half away
// from zero), the shift to the output format and the saturation to int16 run
// in registers: in 32 bits (ADDS, ASR, SSAT) when the exact sum plus half an
// output LSB fits int32, as the gates' sums typically do, else on the 64-bit
// sum out of line.
//
// sigmoid_q15_block / tanh_q15_block: activation.h's table interpolation on
// tables indexed by the signed x (SignedActivationTable below, built at
// compile time from the tanh table), so no |x| and no sign at run time: per
// value one LDR and one LDRSH of the entry, one multiply-add, one SSAT with
// the output shift (one assembly macro for both): 10 instructions; every
// input of both is checked against activation.cc by the exhaustive test.
//
// dot_cols_packed_q15 (W^T g from the packed forward matrix, g int16 block
// floating point): a transposed product needs pairs along the rows, which
// the packed order does not hold in one word, so SMLALD does not apply;
// SMLAL<x><y> takes the int16 halves of W and g straight from their words
// (no unpacking, no split of g): per row pair one word of g, one LDRD of
// each row's four columns, eight SMLAL<x><y>: 12 instructions per 8 MACs.
//
// Shapes outside the fast paths (column counts not a multiple of 8 or 4,
// unaligned rows or vectors, out-of-range shifts) call the reference kernels (reference/dot_q15_reference.h):
// slower, equally exact. All of it is tested bit-exactly against
// fixed_point.h in QEMU (test/boards/kernel_exactness_main.cc).
#include "firmware/core/kernels/dot_q15.h"

#include <cstddef>
#include <cstdint>

#include "firmware/core/activation.h"
#include "firmware/core/kernels/cortex_m4/kernel_layout.h"
#include "firmware/core/kernels/reference/dot_q15_reference.h"

extern "C" {

// Parameter block of hadynet_matvec_pairs (layout shared with the
// assembly, which copies it onto its stack: kernel_layout.h; word offsets in
// the comments).
struct HadynetMatvecJob {
  const std::int32_t* bias;    // 0
  std::int16_t* out;           // 1
  std::int32_t half;           // 2: 2^(out_shift - 1)
  std::int32_t out_shift;      // 3: 1..31
  std::int32_t out_shift_rest; // 4: 32 - out_shift
  std::int32_t pairs;          // 5: row pairs left (>= 1)
  const std::int16_t* a_x;     // 6
  const std::int16_t* a_pair;  // 7: first term's current row pair (the loop ends at the next)
  std::int32_t zeros[4];       // 8..11: 0, the accumulators' start (loaded with a_x and a_pair)
  const std::int16_t* b_x;     // 12
  const std::int16_t* b_pair;  // 13: second term's current row pair
  std::uint32_t a_entry;       // 14: where the unrolled loop starts, | 1 (Thumb)
  std::uint32_t b_entry;       // 15
  std::int32_t a_shift;        // 16: first term's shift relative to the second
  std::int32_t a_shift_rest;   // 17: 32 - a_shift
};

// For each row pair: out = sat16(round((((A . a_x) << a_shift) + B . b_x + bias) >> out_shift)).
void hadynet_matvec_pairs(const HadynetMatvecJob* job) noexcept;
// End labels of the two unrolled loops (entry = end - HADYNET_MVP_BLOCK_BYTES
// * chunks of 8 columns).
extern const char hadynet_mvp_end_a[];
extern const char hadynet_mvp_end_b[];

// In place: v[i] = tanh_q15(v[i]) / sigmoid_q15(v[i]) for n >= 1 values;
// e and d point at entry 0 of a SignedActivationTable.
void hadynet_tanh_block(std::int16_t* v, int n, const std::int32_t* e, const std::int16_t* d) noexcept;
void hadynet_sigmoid_block(std::int16_t* v, int n, const std::int32_t* e, const std::int16_t* d) noexcept;

// out[j] = sum over the `pairs` row pairs p (pairs >= 1) of
// W(2p, j) g[2p] + W(2p + 1, j) g[2p + 1] for j = 0..3, w pointing at
// W(0, j0) of a packed matrix (row 2p + 1 sixteen bytes after row 2p, pairs
// stride_bytes apart); w and g word-aligned.
void hadynet_dot_cols4_q15(const std::int16_t* w, int stride_bytes, const std::int16_t* g, int pairs,
                           std::int64_t* out) noexcept;
}

// The structs are the layout the assembly reads (kernel_layout.h).
static_assert(sizeof(HadynetMatvecJob) == HADYNET_MVP_JOB_BYTES);
static_assert(offsetof(HadynetMatvecJob, bias) == HADYNET_MVP_BIAS);
static_assert(offsetof(HadynetMatvecJob, out) == HADYNET_MVP_OUT);
static_assert(offsetof(HadynetMatvecJob, half) == HADYNET_MVP_HALF);
static_assert(offsetof(HadynetMatvecJob, out_shift) == HADYNET_MVP_OUT_SHIFT);
static_assert(offsetof(HadynetMatvecJob, out_shift_rest) == HADYNET_MVP_OUT_SHIFT_REST);
static_assert(offsetof(HadynetMatvecJob, a_pair) == HADYNET_MVP_A_PAIR);
static_assert(offsetof(HadynetMatvecJob, b_pair) == HADYNET_MVP_B_PAIR);
static_assert(offsetof(HadynetMatvecJob, pairs) == HADYNET_MVP_PAIRS);
static_assert(offsetof(HadynetMatvecJob, a_x) == HADYNET_MVP_A_X);
static_assert(offsetof(HadynetMatvecJob, a_entry) == HADYNET_MVP_A_ENTRY);
static_assert(offsetof(HadynetMatvecJob, zeros) == HADYNET_MVP_ZEROS);
static_assert(offsetof(HadynetMatvecJob, b_x) == HADYNET_MVP_B_X);
static_assert(offsetof(HadynetMatvecJob, b_entry) == HADYNET_MVP_B_ENTRY);
static_assert(offsetof(HadynetMatvecJob, a_shift) == HADYNET_MVP_A_SHIFT);
static_assert(offsetof(HadynetMatvecJob, a_shift_rest) == HADYNET_MVP_A_SHIFT_REST);


namespace hadynet::kernels {
namespace {

constexpr int kMvpMaxCols = 8 * HADYNET_MVP_BLOCKS;
constexpr int kMvpBlockBytes = HADYNET_MVP_BLOCK_BYTES;
// activation.h's interpolation indexed by the signed input. The reference
// (activation.cc) computes, with m = |x|, i = m >> s, f = m mod 2^s,
// T the tanh table and D_i = T[i+1] - T[i]:
//   t(x) = sign(x) (T[i] + floor((D_i f + 2^(s-1)) / 2^s)).
// With j = floor(x / 2^s) and g = x mod 2^s, t = floor((e_j + d_j g) / 2^s)
// for the entries
//   j >= 0 (x >= 0, j = i, g = f):  e_j = 2^s T[j] + 2^(s-1),      d_j = D_j;
//   j = -k < 0 (x < 0):             e_j = -2^s T[k] + 2^(s-1) - 1, d_j = D_(k-1).
// For x < 0 with f > 0, k = i + 1 and g = 2^s - f, so the entry gives
// -T[i+1] + D_i + floor((2^(s-1) - 1 - D_i f) / 2^s)
// = -T[i] - floor((D_i f + 2^(s-1)) / 2^s) (-floor(a / b) = floor((b - 1 - a) / b)),
// and with f = 0 (g = 0, k = i) it gives -T[i]. sigmoid's
// (32768 + t + 1) >> 1 folds in as E_j + 2^s 32769 and a shift by s + 1
// (exact: floor(floor(a / b) / 2) = floor(a / 2b)). The QEMU kernel test
// checks all 65 536 inputs of both against activation.cc.
template <int Shift, bool kSigmoid>
struct SignedActivationTable {
  static constexpr int kEntries = 1 << (16 - Shift);          // j in [-kEntries / 2, kEntries / 2)
  std::int32_t e[kEntries];
  std::int16_t d[kEntries];
  const std::int32_t* e_zero() const noexcept { return e + kEntries / 2; }
  const std::int16_t* d_zero() const noexcept { return d + kEntries / 2; }
};

template <int Shift, bool kSigmoid>
constexpr SignedActivationTable<Shift, kSigmoid> signed_activation_table() noexcept {
  using fixed::detail::kTanhQ15Table;
  SignedActivationTable<Shift, kSigmoid> t{};
  constexpr int kMid = SignedActivationTable<Shift, kSigmoid>::kEntries / 2;
  constexpr std::int32_t kOffset = kSigmoid ? (std::int32_t{32769} << Shift) : 0;
  for (int j = -kMid; j < kMid; ++j) {
    std::int32_t e = 0;
    std::int32_t d = 0;
    if (j >= 0) {
      e = (std::int32_t{kTanhQ15Table[j]} << Shift) + (1 << (Shift - 1));
      d = kTanhQ15Table[j + 1] - kTanhQ15Table[j];
    } else {
      const int k = -j;
      e = -(std::int32_t{kTanhQ15Table[k]} << Shift) + (1 << (Shift - 1)) - 1;
      d = kTanhQ15Table[k] - kTanhQ15Table[k - 1];
    }
    t.e[kMid + j] = e + kOffset;
    t.d[kMid + j] = static_cast<std::int16_t>(d);
  }
  return t;
}

// tanh reads the table at steps of 2^7 input units, sigmoid at 2^8 (tanh(x / 2)).
constexpr auto kTanhSigned = signed_activation_table<7, false>();
constexpr auto kSigmoidSigned = signed_activation_table<8, true>();

inline bool word_aligned(const void* p) noexcept { return (reinterpret_cast<std::uintptr_t>(p) & 3u) == 0; }

std::uint32_t entry(const char* end, int blocks, int block_bytes) noexcept {
  return static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(end) -
                                    static_cast<std::uintptr_t>(blocks * block_bytes)) |
         1u;
}

// A term the assembly can take: a packed matrix (cols a multiple of 8, at
// most kMvpMaxCols) and vector, both word-aligned.
bool fast_term(const MatvecTerm& t) noexcept {
  if (t.cols <= 0) return true;  // absent: zero blocks
  return t.cols % 8 == 0 && t.cols <= kMvpMaxCols && word_aligned(t.w) && word_aligned(t.x) && t.shift >= 0 &&
         t.shift <= 31;
}

}  // namespace

void matvec_requantize_q15(const MatvecTerm& a, const MatvecTerm& b, const std::int32_t* bias, int rows,
                           int out_shift, std::int16_t* out) noexcept {
  if (rows <= 0) return;
  // The assembly shifts only its first term (relative to the second): put
  // the larger shift first; the smaller must be 0.
  const bool swap = b.cols > 0 && (a.cols <= 0 || b.shift > a.shift);
  const MatvecTerm& first = swap ? b : a;
  const MatvecTerm& second = swap ? a : b;
  const bool fast = fast_term(first) && fast_term(second) && (second.cols <= 0 || second.shift == 0) &&
                    out_shift >= 1 && out_shift <= 31 && bias != nullptr;
  if (!fast) {
    reference::matvec_requantize_q15(a, b, bias, rows, out_shift, out);
    return;
  }
  const int first_shift = first.cols > 0 ? first.shift : 0;
  HadynetMatvecJob job = {
      bias,
      out,
      std::int32_t{1} << (out_shift - 1),
      out_shift,
      32 - out_shift,
      rows / 2,
      first.x,
      first.w,
      {0, 0, 0, 0},
      second.x,
      second.w,
      entry(hadynet_mvp_end_a, first.cols / 8, kMvpBlockBytes),
      entry(hadynet_mvp_end_b, second.cols / 8, kMvpBlockBytes),
      first_shift,
      32 - first_shift,
  };
  if (job.pairs > 0) hadynet_matvec_pairs(&job);
  if (rows % 2 != 0) {
    // The last row is the first of a pair whose second row is padding: its
    // two outputs go to a scratch pair.
    const int r = rows - 1;
    std::int16_t pair_out[2];
    job.out = pair_out;
    job.a_pair = first.w + r * first.cols;
    job.b_pair = second.w + r * second.cols;
    job.pairs = 1;
    const std::int32_t pair_bias[2] = {bias[r], 0};
    job.bias = pair_bias;
    hadynet_matvec_pairs(&job);
    out[r] = pair_out[0];
  }
}

void sigmoid_q15_block(std::int16_t* v, int n) noexcept {
  if (n > 0) hadynet_sigmoid_block(v, n, kSigmoidSigned.e_zero(), kSigmoidSigned.d_zero());
}

void tanh_q15_block(std::int16_t* v, int n) noexcept {
  if (n > 0) hadynet_tanh_block(v, n, kTanhSigned.e_zero(), kTanhSigned.d_zero());
}

// W^T g on a packed matrix with int16 g: four columns (inside one chunk of
// eight) at a time over every row pair (hadynet_dot_cols4_q15).
void dot_cols_packed_q15(const std::int16_t* w, int padded_cols, int rows, const std::int16_t* g, int cols,
                         std::int64_t* acc) noexcept {
  if (rows <= 0 || cols % 4 != 0 || !word_aligned(w) || !word_aligned(g)) {
    reference::dot_cols_packed_q15(w, padded_cols, rows, g, cols, acc);
    return;
  }
  const int stride_bytes = 2 * 2 * padded_cols;
  for (int c = 0; c < cols; c += 4)
    hadynet_dot_cols4_q15(w + packed_index(padded_cols, 0, c), stride_bytes, g, (rows + 1) / 2, acc + c);
}

}  // namespace hadynet::kernels
