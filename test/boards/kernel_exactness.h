// Bit-exactness of the build's q15 kernels (kernels/dot_q15.h; on the
// Cortex-M4: the DSP assembly) against the plain reference arithmetic of
// fixed_point.h and activation.h: fixed::dot, fixed::rounding_shift_right,
// fixed::saturate_i16, int64 loops, fixed::tanh_q15 / sigmoid_q15 (all 65536
// inputs). Shared by the mps2-an386 test image (kernel_exactness_main.cc, the
// DSP kernels under QEMU) and the host test (kernel_exactness_host.cc, the
// reference kernels): both print one line per failing case (the first 20)
// and a summary, and fail with the number of failures.
//
// Cases: shapes around the kernels' fast paths and their edges (column
// counts below, at and above multiples of 8 and the unrolled maxima, odd row
// counts (the packed matrices' padding row), matrices and vectors half a
// word off alignment, junk in x beyond a packed matrix's real columns),
// shifts and output shifts including 0 and the largest the kernels accept in
// registers and beyond, and data that stresses the accumulators: uniform
// random, all (-32768)*(-32768) (the largest product, where a 32-bit SMLAD
// overflows), (-32768)*32767, alternating rails, random rail values; biases
// at INT32_MIN and INT32_MAX and sums at the edges of int32 (the forward
// kernel's 32-bit rounding); int16 gradients with junk in the padding entry
// an odd row count reads.
#ifndef HADYNET_TEST_BOARDS_KERNEL_EXACTNESS_H_
#define HADYNET_TEST_BOARDS_KERNEL_EXACTNESS_H_

#include <cstdint>
#include <string_view>

#include "firmware/app/text.h"
#include "firmware/core/activation.h"
#include "firmware/core/fixed_point.h"
#include "firmware/core/kernels/dot_q15.h"

namespace hadynet::test {
// Internal linkage: the header is included by exactly one file per test
// program.
namespace {

using hadynet::app::Text;
namespace kernels = hadynet::kernels;
namespace fixed = hadynet::fixed;

std::uint32_t g_rng = 0x2545F491u;
std::uint32_t next_random() noexcept {
  g_rng ^= g_rng << 13;
  g_rng ^= g_rng >> 17;
  g_rng ^= g_rng << 5;
  return g_rng;
}

enum class Pattern { kRandom, kMinMin, kMinMax, kAlternating, kRails, kCount };
constexpr int kPatterns = static_cast<int>(Pattern::kCount);

std::int16_t value(Pattern p, int i, bool second) noexcept {
  static constexpr std::int16_t kRailValues[] = {-32768, 32767, -32767, -1, 0, 1};
  switch (p) {
    case Pattern::kRandom:
      return static_cast<std::int16_t>(next_random() & 0xFFFFu);
    case Pattern::kMinMin:
      return -32768;
    case Pattern::kMinMax:
      return second ? std::int16_t{32767} : std::int16_t{-32768};
    case Pattern::kAlternating:
      return (i & 1) != 0 ? std::int16_t{-32768} : std::int16_t{32767};
    case Pattern::kRails:
    case Pattern::kCount:
      break;
  }
  return kRailValues[next_random() % 6u];
}

std::int32_t value32(Pattern p) noexcept {
  static constexpr std::int32_t kRails[] = {INT32_MIN,  INT32_MAX,  -1,         0,         1,
                                            0x7FFF7FFF, 0x7FFF8000, static_cast<std::int32_t>(0x80008000u),
                                            1 << 20,    -(1 << 20)};
  switch (p) {
    case Pattern::kRandom:
      return static_cast<std::int32_t>(next_random());
    case Pattern::kMinMin:
      return INT32_MIN;
    case Pattern::kMinMax:
      return 0x7FFF7FFF;
    case Pattern::kAlternating:
      return (next_random() & 1u) != 0 ? INT32_MIN : 0x7FFF7FFF;
    case Pattern::kRails:
    case Pattern::kCount:
      break;
  }
  return kRails[next_random() % 10u];
}

int g_cases = 0;
int g_failures = 0;
void (*g_emit)(std::string_view) = nullptr;

void report_failure(const char* kernel, int rows, int cols, int stride, int pattern, int index, std::int64_t got,
                    std::int64_t want) noexcept {
  ++g_failures;
  if (g_failures > 20) return;
  Text<200> line;
  line << "FAIL " << kernel << " rows=" << rows << " cols=" << cols << " stride=" << stride << " pattern=" << pattern
       << " index=" << index << " got=" << got << " want=" << want << '\n';
  g_emit(line.view());
}

// ---- matvec_requantize_q15 (packed matrices)

constexpr int kMvRows = 40;
constexpr int kMvCols = 264;  // padded columns, at most
std::int16_t g_wa[kMvRows * kMvCols];  // row-major, the reference's view
std::int16_t g_wb[kMvRows * kMvCols];
std::int16_t g_pa[(kMvRows + 1) * kMvCols + 2];  // packed (kernels::packed_index), + half a word
std::int16_t g_pb[(kMvRows + 1) * kMvCols];
std::int16_t g_xa[kMvCols + 2];
std::int16_t g_xb[kMvCols];
std::int32_t g_bias[kMvRows];
std::int16_t g_out[kMvRows + 1];

int padded(int cols) noexcept { return (cols + 7) / 8 * 8; }

// Packs rows x cols of row-major w (zeros in the padding).
void pack(const std::int16_t* w, int rows, int cols, std::int16_t* packed) noexcept {
  const int pc = padded(cols);
  for (int i = 0; i < ((rows + 1) / 2) * 2 * pc; ++i) packed[i] = 0;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) packed[kernels::packed_index(pc, r, c)] = w[r * cols + c];
}

// The reference result of one output (fixed_point.h's exact arithmetic on
// the row-major matrices).
std::int16_t reference_row(int r, int cols_a, int shift_a, int cols_b, int shift_b, std::int32_t bias, int out_shift,
                           const std::int16_t* xa) noexcept {
  std::int64_t acc = bias;
  if (cols_a > 0) acc += fixed::dot(g_wa + r * cols_a, xa, cols_a) * (std::int64_t{1} << shift_a);
  if (cols_b > 0) acc += fixed::dot(g_wb + r * cols_b, g_xb, cols_b) * (std::int64_t{1} << shift_b);
  return fixed::saturate_i16(fixed::rounding_shift_right(acc, out_shift));
}

// |sum| < 2^62 must hold for every input (kernels/dot_q15.h).
bool within_contract(int cols_a, int shift_a, int cols_b, int shift_b) noexcept {
  const double bound = 1073741824.0 * (cols_a * static_cast<double>(std::int64_t{1} << shift_a) +
                                       cols_b * static_cast<double>(std::int64_t{1} << shift_b)) +
                       2147483648.0;
  return bound < 4611686018427387904.0;
}

// offset 1: the packed A matrix and x_a half a word off alignment.
void run_matvec(int rows, int cols_a, int shift_a, int cols_b, int shift_b, int out_shift, int offset,
                Pattern pattern) noexcept {
  for (int i = 0; i < rows * cols_a; ++i) g_wa[i] = value(pattern, i, false);
  for (int i = 0; i < rows * cols_b; ++i) g_wb[i] = value(pattern, i + 1, false);
  pack(g_wa, rows, cols_a, g_pa + offset);
  pack(g_wb, rows, cols_b, g_pb);
  std::int16_t* xa = g_xa + offset;
  // Beyond the real columns x holds junk: it meets the packed zeros.
  for (int i = 0; i < padded(cols_a); ++i) xa[i] = i < cols_a ? value(pattern, i, true) : static_cast<std::int16_t>(next_random());
  for (int i = 0; i < padded(cols_b); ++i) g_xb[i] = i < cols_b ? value(pattern, i + 1, true) : std::int16_t{-32768};
  for (int r = 0; r < rows; ++r) g_bias[r] = value32(pattern == Pattern::kRandom ? Pattern::kRandom : Pattern::kRails);
  for (int r = 0; r <= rows; ++r) g_out[r] = 0x5A5A;
  const kernels::MatvecTerm a{g_pa + offset, padded(cols_a), xa, shift_a};
  const kernels::MatvecTerm b{g_pb, padded(cols_b), g_xb, shift_b};
  kernels::matvec_requantize_q15(a, b, g_bias, rows, out_shift, g_out);
  ++g_cases;
  for (int r = 0; r < rows; ++r) {
    const std::int16_t want = reference_row(r, cols_a, shift_a, cols_b, shift_b, g_bias[r], out_shift, xa);
    if (g_out[r] != want) {
      report_failure("matvec_requantize", rows, cols_a * 1000 + cols_b, out_shift, static_cast<int>(pattern), r,
                     g_out[r], want);
    }
  }
  if (g_out[rows] != 0x5A5A) report_failure("matvec_requantize(overrun)", rows, cols_a, out_shift, 0, rows, g_out[rows], 0x5A5A);
}

void test_matvec() noexcept {
  static constexpr int kRows[] = {1, 2, 3, 27, 40};
  static constexpr int kColsA[] = {0, 1, 7, 8, 16, 45, 128, 256, 260};
  static constexpr int kColsB[] = {0, 8, 127, 128, 256};
  struct Shifts {
    int a, b;
  };
  static constexpr Shifts kShifts[] = {{0, 0}, {2, 0}, {0, 2}, {15, 0}, {0, 31}, {3, 5}};
  static constexpr int kOutShifts[] = {0, 1, 12, 14, 15, 16, 31, 32, 40};
  for (const int rows : kRows) {
    for (const int cols_a : kColsA) {
      for (const int cols_b : kColsB) {
        for (const Shifts s : kShifts) {
          if (!within_contract(padded(cols_a), s.a, padded(cols_b), s.b)) continue;
          for (const int out_shift : kOutShifts) {
            for (int p = 0; p < kPatterns; ++p) {
              // The full pattern set on the main shapes; random data elsewhere.
              if (p != 0 && (out_shift == 1 || out_shift == 40 || rows == 2 || s.a == 3)) continue;
              run_matvec(rows, cols_a, s.a, cols_b, s.b, out_shift, 0, static_cast<Pattern>(p));
            }
          }
          run_matvec(rows, cols_a, s.a, cols_b, s.b, 12, 1, Pattern::kRandom);  // unaligned: the slow path
        }
      }
    }
  }
}

// The forward kernel's 32-bit rounding at the edges of int32: sums (a bias
// plus one product of +-1 or 0) at INT32_MAX, INT32_MIN, within half an
// output LSB of them (where adding half overflows and the 64-bit rounding
// takes over) and just beyond them, for small and large output shifts.
void test_matvec_int32_edges() noexcept {
  constexpr int kRowsEdge = 8;
  constexpr int kCols = 8;
  static constexpr int kOutShifts[] = {1, 2, 12, 15, 16, 17, 31};
  static constexpr std::int16_t kX0[] = {-1, 0, 1};
  for (const int out_shift : kOutShifts) {
    const std::int32_t half = std::int32_t{1} << (out_shift - 1);
    const std::int32_t biases[kRowsEdge] = {INT32_MAX,        INT32_MAX - 1,        INT32_MAX - half, INT32_MAX - half + 1,
                                            INT32_MIN,        INT32_MIN + 1,        -half,            half - 1};
    for (const std::int16_t x0 : kX0) {
      for (int i = 0; i < kRowsEdge * kCols; ++i) g_wb[i] = (i % kCols == 0) ? std::int16_t{1} : std::int16_t{0};
      pack(g_wb, kRowsEdge, kCols, g_pb);
      for (int i = 0; i < kCols; ++i) g_xb[i] = i == 0 ? x0 : std::int16_t{0};
      for (int r = 0; r < kRowsEdge; ++r) g_bias[r] = biases[r];
      for (int r = 0; r <= kRowsEdge; ++r) g_out[r] = 0x5A5A;
      const kernels::MatvecTerm b{g_pb, kCols, g_xb, 0};
      kernels::matvec_requantize_q15({}, b, g_bias, kRowsEdge, out_shift, g_out);
      ++g_cases;
      for (int r = 0; r < kRowsEdge; ++r) {
        const std::int64_t sum = std::int64_t{biases[r]} + x0;
        const std::int16_t want = fixed::saturate_i16(fixed::rounding_shift_right(sum, out_shift));
        if (g_out[r] != want) report_failure("matvec_requantize(int32 edges)", kRowsEdge, x0, out_shift, 0, r, g_out[r], want);
      }
    }
  }
}

// ---- activations: every int16 input, block lengths and alignments

std::int16_t g_act[66];

void test_activations() noexcept {
  for (int start = -32768; start < 32768; start += 64) {
    for (int i = 0; i < 64; ++i) g_act[i] = static_cast<std::int16_t>(start + i);
    kernels::tanh_q15_block(g_act, 64);
    ++g_cases;
    for (int i = 0; i < 64; ++i) {
      const std::int16_t want = fixed::tanh_q15(static_cast<std::int16_t>(start + i));
      if (g_act[i] != want) report_failure("tanh_block", 64, 0, 0, 0, start + i, g_act[i], want);
    }
    for (int i = 0; i < 64; ++i) g_act[i] = static_cast<std::int16_t>(start + i);
    kernels::sigmoid_q15_block(g_act, 64);
    ++g_cases;
    for (int i = 0; i < 64; ++i) {
      const std::int16_t want = fixed::sigmoid_q15(static_cast<std::int16_t>(start + i));
      if (g_act[i] != want) report_failure("sigmoid_block", 64, 0, 0, 0, start + i, g_act[i], want);
    }
  }
  // Lengths 0..3 at an odd halfword offset; the neighbours stay untouched.
  for (int n = 0; n < 4; ++n) {
    for (int i = 0; i < 66; ++i) g_act[i] = static_cast<std::int16_t>(1000 * i - 30000);
    kernels::tanh_q15_block(g_act + 1, n);
    kernels::sigmoid_q15_block(g_act + 1 + n, n);
    ++g_cases;
    for (int i = 0; i < 66; ++i) {
      const auto x = static_cast<std::int16_t>(1000 * i - 30000);
      std::int16_t want = x;
      if (i >= 1 && i < 1 + n) want = fixed::tanh_q15(x);
      if (i >= 1 + n && i < 1 + 2 * n) want = fixed::sigmoid_q15(x);
      if (g_act[i] != want) report_failure("activation_block(edges)", n, 0, 0, 0, i, g_act[i], want);
    }
  }
}

// ---- dot_cols_packed_q15

constexpr int kWtRows = 130;
constexpr int kWtCols = 520;
std::int16_t g_wt[kWtRows * kWtCols + 2];
std::int64_t g_acc[kWtCols];

// W^T g on packed matrices (rows in pairs, columns in chunks of eight) with
// int16 g: against the plain sum over packed_index. Row counts odd (the
// kernel reads g's padding entry, which meets the zero padding row: junk
// there) and even, column counts that are and are not multiples of 4 and 8,
// g half a word off alignment (the slow path).
std::int16_t g_g16[kWtCols + 2];

void test_cols_packed_q15() noexcept {
  static constexpr int kRows[] = {1, 2, 3, 15, 16, 17, 27, 28, 512};
  static constexpr int kCols[] = {0, 1, 4, 5, 8, 12, 13, 128};
  for (const int rows : kRows) {
    for (const int cols : kCols) {
      const int padded = (cols + 7) / 8 * 8;
      const int size = (rows + 1) / 2 * 2 * padded;
      if (size > kWtRows * kWtCols) continue;
      for (int p = 0; p < kPatterns; ++p) {
        for (int offset = 0; offset < 2; ++offset) {
          if (offset != 0 && p != 0) continue;
          const Pattern pattern = static_cast<Pattern>(p);
          for (int i = 0; i < size; ++i) g_wt[i] = 0;
          for (int r = 0; r < rows; ++r)
            for (int c = 0; c < cols; ++c) g_wt[kernels::packed_index(padded, r, c)] = value(pattern, r * cols + c, false);
          std::int16_t* g = g_g16 + offset;
          for (int r = 0; r < rows; ++r) g[r] = value(pattern, r, true);
          g[rows] = static_cast<std::int16_t>(next_random());  // padding: any value
          for (int c = 0; c <= cols; ++c) g_acc[c] = 0x5A5A5A5A5A5A5A5All;
          kernels::dot_cols_packed_q15(g_wt, padded, rows, g, cols, g_acc);
          ++g_cases;
          for (int c = 0; c < cols; ++c) {
            std::int64_t want = 0;
            for (int r = 0; r < rows; ++r)
              want += static_cast<std::int64_t>(g_wt[kernels::packed_index(padded, r, c)]) * g[r];
            if (g_acc[c] != want) report_failure("dot_cols_packed_q15", rows, cols, padded, p, c, g_acc[c], want);
          }
          if (g_acc[cols] != 0x5A5A5A5A5A5A5A5All)
            report_failure("dot_cols_packed_q15(overrun)", rows, cols, padded, p, cols, g_acc[cols], 0);
        }
      }
    }
  }
}

// Runs every case; each failure (the first 20) and the summary line go to
// `emit`. Returns the number of failures.
int run_kernel_exactness(void (*emit)(std::string_view)) noexcept {
  g_emit = emit;
  g_cases = 0;
  g_failures = 0;
  test_matvec();
  test_matvec_int32_edges();
  test_activations();
  test_cols_packed_q15();
  Text<96> line;
  line << "kernel exactness: " << g_cases << " cases, " << g_failures << " failures\n";
  emit(line.view());
  return g_failures;
}

}  // namespace
}  // namespace hadynet::test

#endif  // HADYNET_TEST_BOARDS_KERNEL_EXACTNESS_H_
