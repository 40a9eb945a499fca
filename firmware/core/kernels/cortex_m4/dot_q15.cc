// Cortex-M4 implementation of kernels/dot_q15.h with the DSP extension.
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
// in registers.
//
// sigmoid_q15_block / tanh_q15_block: activation.h's table interpolation
// without branches or calls: |x|, one unaligned LDR for both table entries,
// one multiply, the sign by EOR/SUB; about 16 (tanh) and 19 (sigmoid)
// instructions per value. tanh clamps |x| = 32768 (x = -32768) to 32767 so it
// never reads past the table: exact because the table's last two entries are
// both 32767 (checked, with every other input, by the exhaustive test).
//
// dot_rows_q15_i32 (W^T g with a transposed W): the int32 vector is split
// exactly into int16 halves, g = 2^16 gh + gl with gl the sign-extended low
// half (so gh = (g - gl) / 2^16 fits int16 unless g >= 2^31 - 2^15), stored
// eight gh then eight gl at a time; per eight columns one LDM of W, two LDM
// of g and eight SMLALD into two accumulators: 11 instructions per 8 MACs;
// sum = 2^16 sum_h + sum_l.
//
// dot_cols_q15_i32 (W^T g from W itself, the small decoder matrix): SMLAL
// (32 x 32 + 64) per product, four columns per row of W sharing the load of
// g[r], eight rows unrolled: about 2.56 instructions per MAC.
//
// Shapes outside the fast paths (column counts not a multiple of 8, odd
// strides, unaligned rows or vectors, out-of-range shifts, gradients near
// INT32_MAX) take the plain C++ paths below: slower, equally exact. All of it
// is tested bit-exactly against fixed_point.h in QEMU
// (test/boards/kernel_exactness_main.cc).
#include "firmware/core/kernels/dot_q15.h"

#include <cstdint>

#include "firmware/core/activation.h"

extern "C" {

// Parameter block of hadynet_matvec_pairs (layout shared with the
// assembly, which copies it onto its stack; word offsets in the comments).
struct HadynetMatvecJob {
  const std::int32_t* bias;    // 0
  std::int16_t* out;           // 1
  std::int32_t half;           // 2: 2^(out_shift - 1)
  std::int32_t out_shift;      // 3: 1..31
  std::int32_t out_shift_rest; // 4: 32 - out_shift
  const std::int16_t* a_pair;  // 5: first term's current row pair
  const std::int16_t* b_pair;  // 6: second term's current row pair
  std::int32_t pairs;          // 7: row pairs left (>= 1)
  std::int32_t a_pair_bytes;   // 8: bytes per row pair of A
  std::int32_t b_pair_bytes;   // 9
  const std::int16_t* a_x;     // 10
  std::uint32_t a_entry;       // 11: where the unrolled loop starts, | 1 (Thumb)
  const std::int16_t* b_x;     // 12
  std::uint32_t b_entry;       // 13
  std::int32_t a_shift;        // 14: first term's shift relative to the second
  std::int32_t a_shift_rest;   // 15: 32 - a_shift
};

// For each row pair: out = sat16(round((((A . a_x) << a_shift) + B . b_x + bias) >> out_shift)).
void hadynet_matvec_pairs(const HadynetMatvecJob* job) noexcept;
// End labels of the two unrolled loops (entry = end - 44 * chunks of 8 columns).
extern const char hadynet_mvp_end_a[];
extern const char hadynet_mvp_end_b[];

// In place: v[i] = tanh_q15(v[i]) / sigmoid_q15(v[i]) for n >= 1 values.
void hadynet_tanh_block(std::int16_t* v, int n, const std::int16_t* table) noexcept;
void hadynet_sigmoid_block(std::int16_t* v, int n, const std::int16_t* table) noexcept;

// Parameter block of hadynet_dot_rows_split.
struct HadynetSplitJob {
  const std::int16_t* row;     // 0: current row of W
  std::int32_t rows;           // 1: rows left (>= 1)
  std::int64_t* out;           // 2
  std::int32_t stride;         // 3: bytes
  const std::int16_t* split;   // 4: 8 gh, 8 gl, 8 gh, ... (int16)
  std::uint32_t entry;         // 5: | 1
};
// out[r] = 2^16 * sum W_r gh + sum W_r gl.
void hadynet_dot_rows_split(const HadynetSplitJob* job) noexcept;
extern const char hadynet_split_end[];

// out[j] = sum_{r < rows} w[r * stride + j] g[r] for j = 0..3; rows >= 1.
void hadynet_dot_cols4(const std::int16_t* w, int stride_bytes, const std::int32_t* g, int rows,
                       std::int64_t* out) noexcept;
}

asm(R"(
        .syntax unified
        .thumb
        .text

@ ---------------------------------------------------------------------------
@ hadynet_matvec_pairs(const HadynetMatvecJob* job)
@ One block = eight columns of two rows, eleven 32-bit instructions (44 bytes):
@   r0 x pointer, r1 W pointer (packed), r2-r5 x words, r6-r9 W words,
@   r10:r11 first row's accumulator (low:high), r12:lr the second row's.
        .set    HADYNET_MVP_BLOCKS, 32          @ up to 256 columns per term

        .macro  HADYNET_MVP_BLOCK
        ldmia.w r0!, {r2-r5}
        ldmia.w r1!, {r6-r9}
        smlald  r10, r11, r6, r2
        smlald  r10, r11, r7, r3
        smlald  r10, r11, r8, r4
        smlald  r10, r11, r9, r5
        ldmia.w r1!, {r6-r9}
        smlald  r12, lr, r6, r2
        smlald  r12, lr, r7, r3
        smlald  r12, lr, r8, r4
        smlald  r12, lr, r9, r5
        .endm

@ One row's rounding: acc (lo:hi) + half - (acc < 0), >> out_shift,
@ saturated to int16 into lo. r2 = half, r3 = out_shift, r4 = 32 - out_shift;
@ clobbers r5.
        .macro  HADYNET_MVP_ROUND lo, hi
        asr     r5, \hi, #31
        adds    \lo, \lo, r2
        adc     \hi, \hi, #0
        adds    \lo, \lo, r5
        adc     \hi, \hi, r5
        lsr     \lo, \lo, r3
        lsl     r5, \hi, r4
        orr     \lo, \lo, r5
        asr     \hi, \hi, r3
        cmp     \hi, \lo, asr #31               @ fits int32?
        itee    eq
        ssateq  \lo, #16, \lo                   @ yes: saturate to int16
        movwne  \lo, #0x7fff                    @ no: the rail of its sign
        eorne   \lo, \lo, \hi, asr #31
        .endm

        .global hadynet_matvec_pairs
        .type   hadynet_matvec_pairs, %function
        .thumb_func
        .p2align 2
hadynet_matvec_pairs:
        push    {r4-r11, lr}
        sub     sp, sp, #64
        ldmia   r0!, {r1-r8}                    @ the job onto the stack
        stmia   sp, {r1-r8}
        ldmia   r0, {r1-r8}
        add     r9, sp, #32
        stmia   r9, {r1-r8}
.Lmvp_pair:
        ldr     r1, [sp, #20]                   @ A row pair
        ldr     r0, [sp, #40]                   @ A x
        mov     r10, #0
        mov     r11, #0
        mov     r12, #0
        mov     lr, #0
        ldr     pc, [sp, #44]                   @ into the A loop
        .rept   HADYNET_MVP_BLOCKS
        HADYNET_MVP_BLOCK
        .endr
        .global hadynet_mvp_end_a
hadynet_mvp_end_a:
        ldrd    r8, r9, [sp, #56]               @ both accumulators <<= a_shift
        lsl     r11, r11, r8
        lsr     r2, r10, r9
        orr     r11, r11, r2
        lsl     r10, r10, r8
        lsl     lr, lr, r8
        lsr     r2, r12, r9
        orr     lr, lr, r2
        lsl     r12, r12, r8
        ldr     r1, [sp, #24]                   @ B row pair
        ldr     r0, [sp, #48]                   @ B x
        ldr     pc, [sp, #52]                   @ into the B loop
        .rept   HADYNET_MVP_BLOCKS
        HADYNET_MVP_BLOCK
        .endr
        .global hadynet_mvp_end_b
hadynet_mvp_end_b:
        ldmia   sp, {r0-r4}                     @ bias, out, half, out_shift, 32 - out_shift
        ldrd    r6, r7, [r0], #8                @ the pair's biases, sign-extended in
        adds    r10, r10, r6
        adc     r11, r11, r6, asr #31
        adds    r12, r12, r7
        adc     lr, lr, r7, asr #31
        HADYNET_MVP_ROUND r10, r11
        HADYNET_MVP_ROUND r12, lr
        strh    r10, [r1], #2
        strh    r12, [r1], #2
        stmia   sp, {r0-r1}
        add     r5, sp, #20                     @ next row pair
        ldmia   r5, {r6-r10}                    @ A pair, B pair, pairs, A/B pair bytes
        add     r6, r6, r9
        add     r7, r7, r10
        subs    r8, r8, #1
        stmia   r5, {r6-r8}
        bne     .Lmvp_pair
        add     sp, sp, #64
        pop     {r4-r11, pc}
        .size   hadynet_matvec_pairs, . - hadynet_matvec_pairs

@ ---------------------------------------------------------------------------
@ hadynet_tanh_block(v, n, table) / hadynet_sigmoid_block(v, n, table)
@ activation.h: m = |x|; tanh(m / 2^(shift + 5)) = T[i] + ((T[i+1] - T[i]) f
@ + 2^(shift - 1)) >> shift with i = m >> shift, f = m mod 2^shift (f = 0
@ gives T[i]); negated for x < 0. tanh: shift 7. sigmoid: shift 8, then
@ (32768 + t + 1) >> 1, at most 32767.
@   r0 v, r1 n, r2 table, r3 x, r4 m / f, r5 i / d, r6 T[i] | T[i+1] << 16,
@   r7 y, r8 32769 (sigmoid).
        .global hadynet_tanh_block
        .type   hadynet_tanh_block, %function
        .thumb_func
        .p2align 2
hadynet_tanh_block:
        push    {r4-r7}
1:
        ldrsh   r3, [r0]
        eor     r4, r3, r3, asr #31
        sub     r4, r4, r3, asr #31
        usat    r4, #15, r4                     @ m = min(|x|, 32767): i <= 255
        lsr     r5, r4, #7
        and     r4, r4, #127
        ldr     r6, [r2, r5, lsl #1]
        sxth    r7, r6
        rsb     r5, r7, r6, asr #16
        mul     r5, r5, r4
        add     r5, r5, #64
        add     r7, r7, r5, asr #7
        eor     r7, r7, r3, asr #31
        sub     r7, r7, r3, asr #31
        strh    r7, [r0], #2
        subs    r1, r1, #1
        bne     1b
        pop     {r4-r7}
        bx      lr
        .size   hadynet_tanh_block, . - hadynet_tanh_block

        .global hadynet_sigmoid_block
        .type   hadynet_sigmoid_block, %function
        .thumb_func
        .p2align 2
hadynet_sigmoid_block:
        push    {r4-r8}
        movw    r8, #32769
1:
        ldrsh   r3, [r0]
        eor     r4, r3, r3, asr #31
        sub     r4, r4, r3, asr #31             @ m = |x| <= 32768: i <= 128
        lsr     r5, r4, #8
        and     r4, r4, #255
        ldr     r6, [r2, r5, lsl #1]
        sxth    r7, r6
        rsb     r5, r7, r6, asr #16
        mul     r5, r5, r4
        add     r5, r5, #128
        add     r7, r7, r5, asr #8
        eor     r7, r7, r3, asr #31
        sub     r7, r7, r3, asr #31
        add     r7, r7, r8
        asr     r7, r7, #1
        ssat    r7, #16, r7
        strh    r7, [r0], #2
        subs    r1, r1, #1
        bne     1b
        pop     {r4-r8}
        bx      lr
        .size   hadynet_sigmoid_block, . - hadynet_sigmoid_block

@ ---------------------------------------------------------------------------
@ hadynet_dot_rows_split(const HadynetSplitJob* job)
@ One block = eight columns, eleven 32-bit instructions (44 bytes):
@   r0 split-g pointer, r1 W pointer, r2-r5 g words, r6-r9 W words,
@   r10:r11 sum of W gh, r12:lr sum of W gl.
        .set    HADYNET_SPLIT_BLOCKS, 64        @ up to 512 columns

        .macro  HADYNET_SPLIT_BLOCK
        ldmia.w r1!, {r6-r9}
        ldmia.w r0!, {r2-r5}
        smlald  r10, r11, r6, r2
        smlald  r10, r11, r7, r3
        smlald  r10, r11, r8, r4
        smlald  r10, r11, r9, r5
        ldmia.w r0!, {r2-r5}
        smlald  r12, lr, r6, r2
        smlald  r12, lr, r7, r3
        smlald  r12, lr, r8, r4
        smlald  r12, lr, r9, r5
        .endm

        .global hadynet_dot_rows_split
        .type   hadynet_dot_rows_split, %function
        .thumb_func
        .p2align 2
hadynet_dot_rows_split:
        push    {r4-r11, lr}
        sub     sp, sp, #24
        ldmia   r0, {r1-r6}
        stmia   sp, {r1-r6}
.Lsplit_row:
        ldr     r1, [sp, #0]                    @ W row
        ldr     r0, [sp, #16]                   @ split g
        mov     r10, #0
        mov     r11, #0
        mov     r12, #0
        mov     lr, #0
        ldr     pc, [sp, #20]
        .rept   HADYNET_SPLIT_BLOCKS
        HADYNET_SPLIT_BLOCK
        .endr
        .global hadynet_split_end
hadynet_split_end:
        lsl     r11, r11, #16                   @ 2^16 sum_h + sum_l
        orr     r11, r11, r10, lsr #16
        lsl     r10, r10, #16
        adds    r10, r10, r12
        adc     r11, r11, lr
        ldmia   sp, {r2-r5}                     @ r2 row, r3 rows, r4 out, r5 stride
        strd    r10, r11, [r4], #8
        add     r2, r2, r5
        subs    r3, r3, #1
        stmia   sp, {r2-r4}
        bne     .Lsplit_row
        add     sp, sp, #24
        pop     {r4-r11, pc}
        .size   hadynet_dot_rows_split, . - hadynet_dot_rows_split

@ ---------------------------------------------------------------------------
@ hadynet_dot_cols4(w, stride_bytes, g, rows, out)
@ One row of W^T g: four columns (r0 points at W[r][c]), g[r] shared.
@ Ten 32-bit instructions (40 bytes):
@   r0 W pointer, r1 stride in bytes, r2 g pointer, r3 passes of 8 rows,
@   r4 g[r], r5 W value, r6:r7, r8:r9, r10:r11, r12:lr accumulators.
        .macro  HADYNET_COLS_ROW
        ldr.w   r4, [r2], #4
        ldrsh.w r5, [r0, #0]
        smlal   r6, r7, r5, r4
        ldrsh.w r5, [r0, #2]
        smlal   r8, r9, r5, r4
        ldrsh.w r5, [r0, #4]
        smlal   r10, r11, r5, r4
        ldrsh.w r5, [r0, #6]
        smlal   r12, lr, r5, r4
        add.w   r0, r0, r1
        .endm

        .global hadynet_dot_cols4
        .type   hadynet_dot_cols4, %function
        .thumb_func
        .p2align 2
hadynet_dot_cols4:
        push    {r4-r11, lr}
        mov     r6, #0
        mov     r7, #0
        mov     r8, #0
        mov     r9, #0
        mov     r10, #0
        mov     r11, #0
        mov     r12, #0
        mov     lr, #0
        @ Enter the 8-row body so that the first pass does rows % 8 rows
        @ (8 if rows % 8 == 0); r3 becomes the number of passes.
        and     r4, r3, #7
        adds    r3, r3, #7
        lsrs    r3, r3, #3
        cbz     r4, 3f
        rsb     r4, r4, #8
        mov     r5, #40
        mul     r4, r4, r5
        adr.w   r5, 1f
        add     r4, r4, r5
        orr     r4, r4, #1
        bx      r4
3:
1:
        .rept   8
        HADYNET_COLS_ROW
        .endr
        subs    r3, r3, #1
        bne     1b
        ldr     r4, [sp, #36]
        strd    r6, r7, [r4]
        strd    r8, r9, [r4, #8]
        strd    r10, r11, [r4, #16]
        strd    r12, lr, [r4, #24]
        pop     {r4-r11, pc}
        .size   hadynet_dot_cols4, . - hadynet_dot_cols4
)");

namespace hadynet::kernels {
namespace {

constexpr int kMvpMaxCols = 8 * 32;      // HADYNET_MVP_BLOCKS
constexpr int kMvpBlockBytes = 44;
constexpr int kSplitMaxCols = 8 * 64;    // HADYNET_SPLIT_BLOCKS
constexpr int kSplitBlockBytes = 44;
// g >= 2^31 - 2^15 has no int16 high half (gh would be 2^15).
constexpr std::int32_t kSplitMax = 0x7FFF7FFF;

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

std::int64_t plain_term(const MatvecTerm& t, int r) noexcept {
  std::int64_t sum = 0;
  for (int c = 0; c < t.cols; ++c) sum += std::int32_t{t.w[packed_index(t.cols, r, c)]} * std::int32_t{t.x[c]};
  return sum * (std::int64_t{1} << t.shift);
}

// Round half away from zero, then saturate to int16 (fixed::requantize_i16).
std::int16_t requantize(std::int64_t acc, int shift) noexcept {
  if (shift > 0) {
    const std::int64_t half = std::int64_t{1} << (shift - 1);
    acc = (acc + half - (acc < 0 ? 1 : 0)) >> shift;  // arithmetic shift: floor
  }
  if (acc > 32767) return 32767;
  if (acc < -32768) return -32768;
  return static_cast<std::int16_t>(acc);
}

// The split of g for hadynet_dot_rows_split (static: the firmware is
// single-threaded and nothing here is reentrant).
alignas(8) std::int16_t g_split[2 * kSplitMaxCols];

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
    for (int r = 0; r < rows; ++r) {
      out[r] = requantize(std::int64_t{bias[r]} + plain_term(a, r) + plain_term(b, r), out_shift);
    }
    return;
  }
  const int first_shift = first.cols > 0 ? first.shift : 0;
  HadynetMatvecJob job = {
      bias,
      out,
      std::int32_t{1} << (out_shift - 1),
      out_shift,
      32 - out_shift,
      first.w,
      second.w,
      rows / 2,
      4 * first.cols,
      4 * second.cols,
      first.x,
      entry(hadynet_mvp_end_a, first.cols / 8, kMvpBlockBytes),
      second.x,
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
  if (n > 0) hadynet_sigmoid_block(v, n, fixed::detail::kTanhQ15Table);
}

void tanh_q15_block(std::int16_t* v, int n) noexcept {
  if (n > 0) hadynet_tanh_block(v, n, fixed::detail::kTanhQ15Table);
}

void dot_rows_q15_i32(const std::int16_t* w, int stride, int rows, const std::int32_t* x, int cols,
                      std::int64_t* acc) noexcept {
  if (rows <= 0) return;
  bool fast = cols > 0 && cols % 8 == 0 && cols <= kSplitMaxCols && word_aligned(w) && (stride & 1) == 0;
  if (fast) {
    // g = 2^16 gh + gl, gl the sign-extended low half; eight gh, eight gl, ...
    for (int c0 = 0; c0 < cols && fast; c0 += 8) {
      std::int16_t* block = g_split + 2 * c0;
      for (int i = 0; i < 8; ++i) {
        const std::int32_t g = x[c0 + i];
        if (g > kSplitMax) {
          fast = false;
          break;
        }
        const auto low = static_cast<std::int16_t>(static_cast<std::uint32_t>(g) & 0xFFFFu);
        block[i] = static_cast<std::int16_t>((g - low) / 65536);  // exact: g - low is a multiple of 2^16
        block[8 + i] = low;
      }
    }
  }
  if (!fast) {
    for (int r = 0; r < rows; ++r) {
      const std::int16_t* row = w + r * stride;
      std::int64_t sum = 0;
      for (int c = 0; c < cols; ++c) sum += std::int64_t{row[c]} * x[c];
      acc[r] = sum;
    }
    return;
  }
  const HadynetSplitJob job = {w, rows, acc, 2 * stride, g_split, entry(hadynet_split_end, cols / 8, kSplitBlockBytes)};
  hadynet_dot_rows_split(&job);
}

void dot_cols_q15_i32(const std::int16_t* w, int stride, int rows, const std::int32_t* g, int cols,
                      std::int64_t* acc) noexcept {
  int c = 0;
  if (rows > 0) {
    for (; c + 4 <= cols; c += 4) hadynet_dot_cols4(w + c, 2 * stride, g, rows, acc + c);
  }
  for (; c < cols; ++c) {
    std::int64_t a = 0;
    for (int r = 0; r < rows; ++r) a += static_cast<std::int64_t>(w[r * stride + c]) * g[r];
    acc[c] = a;
  }
}

}  // namespace hadynet::kernels
