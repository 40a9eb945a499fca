// Fixed-point arithmetic for the quantised HADYNET network (docs/architecture.md §6).
//
// This is the *reference kernel* (docs/architecture.md §6): plain, readable integer
// code that optimised kernels (e.g. Cortex-M DSP, `kernels/cortex_m4/`) are
// tested against bit-exactly. Do not optimise it in place.
//
// Freestanding C++20: no heap, no exceptions, no RTTI, no I/O, no target
// #ifdefs. The same source builds for the host (host-sim, tests) and the MCU,
// and gives bit-identical results on both.
//
// Conventions used by every function below:
//  * A Q(F) value is an integer v standing for the real number v / 2^F.
//    Activations and weights are int16 Q(F) with 0 <= F <= 15
//    (range [-2^(15-F), 2^(15-F) - 2^-F], resolution 2^-F = 1 LSB).
//  * Products of Q(a) and Q(b) are Q(a+b). Accumulators are int64 and hold
//    dot products *exactly*: |int16 * int16| <= 2^30 and at most 2^31 - 1
//    terms (n is an int) plus one int32 bias stay below 2^62, so the sum never
//    overflows and does not depend on summation order. Saturation happens
//    only when a result is narrowed (to int16 or int32).
//  * Rounding: round to nearest, ties away from zero ("round half away from
//    zero", like std::round) — everywhere: requantisation, multiplication,
//    and real -> Q conversion. Example: 2.5 -> 3, -2.5 -> -3, 2.4 -> 2.
//  * Saturation: results outside the destination type clamp to its minimum
//    or maximum; nothing ever wraps.
//  * Right shifts of negative integers are arithmetic (guaranteed by C++20).
#ifndef HADYNET_FIRMWARE_CORE_FIXED_POINT_H_
#define HADYNET_FIRMWARE_CORE_FIXED_POINT_H_

#include <cstdint>
#include <limits>
#include <type_traits>

namespace hadynet::fixed {

// Exact int64 accumulator of products in Q(a+b) (see conventions above).
using Accumulator = std::int64_t;

// ---------------------------------------------------------------------------
// Format description
// ---------------------------------------------------------------------------

// An int16 Q format with FracBits fractional bits: real = raw / 2^FracBits.
// Codegen picks FracBits per tensor from measured ranges and writes them into
// the generated model constants; kernels take the bare `int` frac-bit counts
// (e.g. `QFormat<12>::frac_bits`) as template arguments.
template <int FracBits>
struct QFormat {
  static_assert(FracBits >= 0 && FracBits <= 15, "int16 Q format needs 0 <= FracBits <= 15");
  using Raw = std::int16_t;
  static constexpr int frac_bits = FracBits;
  static constexpr int int_bits = 15 - FracBits;  // excluding the sign bit
  static constexpr Raw raw_min = std::numeric_limits<Raw>::min();
  static constexpr Raw raw_max = std::numeric_limits<Raw>::max();
  // Raw value of 1.0, or raw_max if 1.0 is not representable (FracBits = 15).
  static constexpr Raw raw_one =
      FracBits == 15 ? raw_max : static_cast<Raw>(std::int32_t{1} << FracBits);
};

// ---------------------------------------------------------------------------
// Saturating narrowing
// ---------------------------------------------------------------------------

template <typename T>
concept SignedInteger = std::is_integral_v<T> && std::is_signed_v<T>;

// Clamps x into the range of To. Never wraps. To and From are signed integer
// types (int8..int64); any combination is allowed.
template <SignedInteger To, SignedInteger From>
[[nodiscard]] constexpr To saturate_cast(From x) noexcept {
  if constexpr (std::numeric_limits<From>::digits <= std::numeric_limits<To>::digits) {
    return static_cast<To>(x);  // widening or same width: always exact
  } else {
    if (x > static_cast<From>(std::numeric_limits<To>::max())) {
      return std::numeric_limits<To>::max();
    }
    if (x < static_cast<From>(std::numeric_limits<To>::min())) {
      return std::numeric_limits<To>::min();
    }
    return static_cast<To>(x);
  }
}

// Saturating narrowing to int16 from int32 or int64 (or any signed integer).
template <SignedInteger From>
[[nodiscard]] constexpr std::int16_t saturate_i16(From x) noexcept {
  return saturate_cast<std::int16_t>(x);
}

// Saturating narrowing to int32 from int64 (or any signed integer).
template <SignedInteger From>
[[nodiscard]] constexpr std::int32_t saturate_i32(From x) noexcept {
  return saturate_cast<std::int32_t>(x);
}

// ---------------------------------------------------------------------------
// Saturating add / sub (operands and result in the same Q format)
// ---------------------------------------------------------------------------

// a + b, clamped to [INT16_MIN, INT16_MAX].
[[nodiscard]] constexpr std::int16_t add_sat(std::int16_t a, std::int16_t b) noexcept {
  return saturate_i16(std::int32_t{a} + std::int32_t{b});
}

// a - b, clamped to [INT16_MIN, INT16_MAX].
[[nodiscard]] constexpr std::int16_t sub_sat(std::int16_t a, std::int16_t b) noexcept {
  return saturate_i16(std::int32_t{a} - std::int32_t{b});
}

// a + b, clamped to [INT32_MIN, INT32_MAX].
[[nodiscard]] constexpr std::int32_t add_sat32(std::int32_t a, std::int32_t b) noexcept {
  return saturate_i32(std::int64_t{a} + std::int64_t{b});
}

// a - b, clamped to [INT32_MIN, INT32_MAX].
[[nodiscard]] constexpr std::int32_t sub_sat32(std::int32_t a, std::int32_t b) noexcept {
  return saturate_i32(std::int64_t{a} - std::int64_t{b});
}

// ---------------------------------------------------------------------------
// Multiply-accumulate
// ---------------------------------------------------------------------------

// acc + a * b, exact. a in Q(fa), b in Q(fb), acc and result in Q(fa+fb).
// Cannot overflow for the accumulation lengths this header allows (see top).
[[nodiscard]] constexpr Accumulator mac(Accumulator acc, std::int16_t a, std::int16_t b) noexcept {
  return acc + std::int64_t{std::int32_t{a} * std::int32_t{b}};
}

// acc + a * b with an int32 accumulator, saturating at INT32_MIN/INT32_MAX
// after each step (like the Cortex-M QADD of a SMULBB product). The product
// itself always fits in int32 (|a*b| <= 2^30). Note that a chain of saturating
// steps depends on order; the kernels below use the exact `mac` instead.
[[nodiscard]] constexpr std::int32_t mac_sat32(std::int32_t acc, std::int16_t a, std::int16_t b) noexcept {
  return saturate_i32(std::int64_t{acc} + std::int64_t{std::int32_t{a} * std::int32_t{b}});
}

// ---------------------------------------------------------------------------
// Rounding shifts and requantisation
// ---------------------------------------------------------------------------

// x / 2^shift rounded to nearest, ties away from zero. 0 <= shift <= 62.
// Exact for every int64 x (no intermediate overflow, no negation of INT64_MIN).
[[nodiscard]] constexpr std::int64_t rounding_shift_right(std::int64_t x, int shift) noexcept {
  if (shift <= 0) {
    return x;
  }
  const std::int64_t floor_q = x >> shift;  // arithmetic: floor(x / 2^shift)
  const std::int64_t mask = (std::int64_t{1} << shift) - 1;
  const std::int64_t rem = x & mask;  // x - floor_q * 2^shift, in [0, 2^shift)
  const std::int64_t half = std::int64_t{1} << (shift - 1);
  // rem > half: nearest is above. rem == half (tie): for x >= 0 away from
  // zero is up; for x < 0 floor already is away from zero.
  if (rem > half || (rem == half && x >= 0)) {
    return floor_q + 1;  // cannot overflow: floor_q <= INT64_MAX >> 1
  }
  return floor_q;
}

// x * 2^shift, saturated to [INT64_MIN, INT64_MAX]. 0 <= shift <= 62.
[[nodiscard]] constexpr std::int64_t saturating_shift_left(std::int64_t x, int shift) noexcept {
  if (shift <= 0) {
    return x;
  }
  constexpr std::int64_t max = std::numeric_limits<std::int64_t>::max();
  constexpr std::int64_t min = std::numeric_limits<std::int64_t>::min();
  if (x > (max >> shift)) {
    return max;
  }
  if (x < (min >> shift)) {  // min >> shift == -2^(63-shift) exactly
    return min;
  }
  return x * (std::int64_t{1} << shift);  // in range: exact
}

// Rescales an int64 value from Q(FromFrac) to Q(ToFrac): rounds half away
// from zero when dropping bits, saturates to int64 when adding bits.
// Result is int64 (narrow it with saturate_i16/_i32 or use requantize_*).
template <int FromFrac, int ToFrac>
[[nodiscard]] constexpr std::int64_t rescale(std::int64_t x) noexcept {
  static_assert(FromFrac >= 0 && ToFrac >= 0, "frac bits are non-negative");
  static_assert(FromFrac - ToFrac <= 62 && ToFrac - FromFrac <= 62, "shift out of range");
  if constexpr (FromFrac >= ToFrac) {
    return rounding_shift_right(x, FromFrac - ToFrac);
  } else {
    return saturating_shift_left(x, ToFrac - FromFrac);
  }
}

// Accumulator (or any integer) in Q(FromFrac) -> int16 in Q(ToFrac):
// round half away from zero, then saturate to [INT16_MIN, INT16_MAX].
// Typical use: FromFrac = weight_frac + input_frac, ToFrac = output_frac.
template <int FromFrac, int ToFrac>
[[nodiscard]] constexpr std::int16_t requantize_i16(std::int64_t acc) noexcept {
  static_assert(ToFrac <= 15, "int16 output format needs ToFrac <= 15");
  return saturate_i16(rescale<FromFrac, ToFrac>(acc));
}

// As requantize_i16 but to an int32 in Q(ToFrac), saturating to int32.
template <int FromFrac, int ToFrac>
[[nodiscard]] constexpr std::int32_t requantize_i32(std::int64_t acc) noexcept {
  return saturate_i32(rescale<FromFrac, ToFrac>(acc));
}

// Element-wise product: a in Q(AFrac), b in Q(BFrac) -> Q(YFrac), rounded half
// away from zero and saturated (e.g. LSTM f*c, i*g, o*tanh(c)).
template <int AFrac, int BFrac, int YFrac>
[[nodiscard]] constexpr std::int16_t mul(std::int16_t a, std::int16_t b) noexcept {
  return requantize_i16<AFrac + BFrac, YFrac>(mac(0, a, b));
}

// ---------------------------------------------------------------------------
// Real <-> Q conversion (reference, tests and codegen; not the hot path)
// ---------------------------------------------------------------------------

// real * 2^Frac rounded half away from zero, saturated to Int's range.
// NaN -> 0; +inf -> max; -inf -> min. Real is float or double.
template <SignedInteger Int, int Frac, typename Real>
[[nodiscard]] constexpr Int real_to_fixed(Real real) noexcept {
  static_assert(std::is_floating_point_v<Real>, "Real must be float or double");
  static_assert(Frac >= 0 && Frac <= 62, "frac bits out of range");
  if (real != real) {  // NaN
    return 0;
  }
  // Multiplying by a power of two is exact (barring overflow to inf, which
  // the clamp below handles).
  const Real v = real * static_cast<Real>(std::int64_t{1} << Frac);
  // Anything beyond +-2^62 saturates every supported Int; clamping first keeps
  // the int64 conversion below defined.
  constexpr Real limit = static_cast<Real>(std::int64_t{1} << 62);
  if (v >= limit) {
    return std::numeric_limits<Int>::max();
  }
  if (v <= -limit) {
    return std::numeric_limits<Int>::min();
  }
  std::int64_t whole = static_cast<std::int64_t>(v);  // truncates toward zero
  const Real frac = v - static_cast<Real>(whole);     // exact, in (-1, 1)
  if (frac >= static_cast<Real>(0.5)) {
    ++whole;
  } else if (frac <= static_cast<Real>(-0.5)) {
    --whole;
  }
  return saturate_cast<Int>(whole);
}

// int16 Q(Frac) from a real value (see real_to_fixed for rounding/saturation).
template <int Frac, typename Real>
[[nodiscard]] constexpr std::int16_t to_q(Real real) noexcept {
  static_assert(Frac >= 0 && Frac <= 15, "int16 Q format needs 0 <= Frac <= 15");
  return real_to_fixed<std::int16_t, Frac>(real);
}

// Real value of a Q(Frac) integer (int16, int32 or int64). Exact for int16
// and int32 in double, for int16 in float.
template <int Frac, typename Real = float, SignedInteger Int>
[[nodiscard]] constexpr Real to_real(Int q) noexcept {
  static_assert(std::is_floating_point_v<Real>, "Real must be float or double");
  static_assert(Frac >= 0 && Frac <= 62, "frac bits out of range");
  return static_cast<Real>(q) / static_cast<Real>(std::int64_t{1} << Frac);
}

// ---------------------------------------------------------------------------
// Reference kernels
// ---------------------------------------------------------------------------

// Exact dot product sum_i a[i] * b[i]. a in Q(fa), b in Q(fb), result in
// Q(fa+fb). n >= 0; n <= 0 returns 0.
[[nodiscard]] constexpr Accumulator dot(const std::int16_t* a, const std::int16_t* b, int n) noexcept {
  Accumulator acc = 0;
  for (int i = 0; i < n; ++i) {
    acc = mac(acc, a[i], b[i]);
  }
  return acc;
}

// Exact dot product of two length-N arrays (see the pointer overload).
template <int N>
[[nodiscard]] constexpr Accumulator dot(const std::int16_t (&a)[N], const std::int16_t (&b)[N]) noexcept {
  static_assert(N > 0, "empty dot product");
  return dot(a, b, N);
}

// Dot product of two Q15 vectors of length n: exact sum in Q30, saturated to
// int32 (saturates only if the real sum leaves [-2, 2)). n <= 0 returns 0.
[[nodiscard]] constexpr std::int32_t dot_q15(const std::int16_t* a, const std::int16_t* b, int n) noexcept {
  return saturate_i32(dot(a, b, n));
}

// As above for two length-N arrays.
template <int N>
[[nodiscard]] constexpr std::int32_t dot_q15(const std::int16_t (&a)[N], const std::int16_t (&b)[N]) noexcept {
  static_assert(N > 0, "empty dot product");
  return dot_q15(a, b, N);
}

// acc[r] += sum_c w[r][c] * x[c] for every row, exact.
// w in Q(fw), x in Q(fx), acc in Q(fw+fx). Lets one output sum several
// matrix-vector products before a single rounding (e.g. the LSTM gates
// W_ih [u;p] + W_hh h + b, with both input vectors in the same format).
template <int Rows, int Cols>
constexpr void matvec_accumulate(const std::int16_t (&w)[Rows][Cols], const std::int16_t (&x)[Cols],
                                 Accumulator (&acc)[Rows]) noexcept {
  static_assert(Rows > 0 && Cols > 0, "empty matrix");
  for (int r = 0; r < Rows; ++r) {
    acc[r] += dot(w[r], x);
  }
}

// y = saturate(round(W x + bias)) per row:
//   w    int16 Q(WFrac), Rows x Cols, row-major (PyTorch `weight` layout)
//   x    int16 Q(XFrac), Cols
//   bias int32 Q(WFrac + XFrac) — already in accumulator format, so adding it
//        is exact (codegen quantises the float bias with real_to_fixed)
//   y    int16 Q(YFrac), Rows
// The row sum is exact in int64; the only rounding is the final requantise
// from Q(WFrac+XFrac) to Q(YFrac) (half away from zero, <= 0.5 LSB of y), then
// saturation to int16. x and y must not alias.
template <int WFrac, int XFrac, int YFrac, int Rows, int Cols>
constexpr void matvec(const std::int16_t (&w)[Rows][Cols], const std::int16_t (&x)[Cols],
                      const std::int32_t (&bias)[Rows], std::int16_t (&y)[Rows]) noexcept {
  static_assert(Rows > 0 && Cols > 0, "empty matrix");
  static_assert(WFrac >= 0 && WFrac <= 15 && XFrac >= 0 && XFrac <= 15, "int16 Q formats");
  static_assert(YFrac >= 0 && YFrac <= 15, "int16 output format");
  for (int r = 0; r < Rows; ++r) {
    const Accumulator acc = Accumulator{bias[r]} + dot(w[r], x);
    y[r] = requantize_i16<WFrac + XFrac, YFrac>(acc);
  }
}

}  // namespace hadynet::fixed

#endif  // HADYNET_FIRMWARE_CORE_FIXED_POINT_H_
