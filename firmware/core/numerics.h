// The two numerics of a generated model (model_contract.h), behind one set of
// names so that the network, detector and controller are written once:
//   q15: Value int16 in a Q format, accumulators int64 (exact), gradients
//        int32 at one common scale, every narrowing rounded and saturated
//        (fixed_point.h);
//   f32: Value, accumulators and gradients float.
// Frac-bit template arguments are ignored by the f32 versions.
#ifndef HADYNET_FIRMWARE_CORE_NUMERICS_H_
#define HADYNET_FIRMWARE_CORE_NUMERICS_H_

#include <bit>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "firmware/core/activation.h"
#include "firmware/core/bounded_rounding.h"
#include "firmware/core/fixed_point.h"
#include "firmware/core/model_contract.h"

namespace hadynet::firmware {

template <class M>
inline constexpr bool kIsFixed = M::kNumeric == Numeric::kQ15;

// Gradient scale of the q15 controller: gradients are int32 with this many
// fractional bits after the loss gradient has been scaled so that its
// largest entry is 1.0 (see grasp_stabilizer.h). 2^20 leaves 11 bits of
// headroom for growth through the network before saturation.
inline constexpr int kGradFracBits = 20;

// Number of bits of v > 0 (floor(log2 v) + 1).
constexpr int bit_length(std::int64_t v) noexcept {
  return static_cast<int>(std::bit_width(static_cast<std::uint64_t>(v)));
}

// The q15 loss-gradient scaling shared by the stabiliser and PB
// adaptation: the right shift that brings the largest magnitude max_abs
// (> 0) into [2^kGradFracBits, 2^(kGradFracBits + 1)) ...
constexpr int grad_scale_shift(std::int64_t max_abs) noexcept { return bit_length(max_abs) - (kGradFracBits + 1); }
// ... and v scaled by it (rounded; a negative shift is a left shift), as an int32 gradient.
constexpr std::int32_t grad_scaled(std::int64_t v, int shift) noexcept {
  return static_cast<std::int32_t>(shift >= 0 ? fixed::rounding_shift_right(v, shift) : v * (std::int64_t{1} << -shift));
}

// Gradients as the backward kernels read them (kernels::dot_cols_packed_q15):
// block floating point, int16 mantissas out[i] = saturate_i16(round(g[i] /
// 2^s)) of n int32 gradients with one exponent s >= 0, returned: the
// smallest s for which the largest |g| has at most 15 bits. s = 0 (exact)
// while every |g| < 2^15; otherwise each mantissa is within half an LSB of
// g / 2^s, 2^-15 of the largest. The caller multiplies the kernel's sums by
// 2^s (exact in int64; for at most 2^13 rows |sum 2^s| < 2^60, the bound
// HadynetNet's BlockGrad asserts for fixed::bounded's rounding).
inline int grad_block_q15(const std::int32_t* g, int n, std::int16_t* out) noexcept {
  // The bit length of the largest |g| is that of the OR of all |g| (the
  // same highest bit), which needs no compare per value.
  std::uint32_t magnitude_bits = 0;
  for (int i = 0; i < n; ++i)
    magnitude_bits |= g[i] < 0 ? 0u - static_cast<std::uint32_t>(g[i]) : static_cast<std::uint32_t>(g[i]);
  const int length = static_cast<int>(std::bit_width(magnitude_bits));
  const int s = length > 15 ? length - 15 : 0;
  if (s == 0) {
    for (int i = 0; i < n; ++i) out[i] = static_cast<std::int16_t>(g[i]);
    return 0;
  }
  // fixed::rounding_shift_right, written as (g + half - [g < 0]) >> s (equal
  // for |g| < 2^62; GradBlockQ15.* checks it): calling the reference here
  // costs the q15 control period 0.1 M and detect + adaptation 0.2 M more
  // instructions (bench/qemu_icount.sh). For s <= 15 every |g| < 2^30, so
  // the sum fits int32 (a 64-bit shift by a run-time s costs the Cortex-M4
  // about 13 more instructions per value); s = 16, 17 only for |g| >= 2^30.
  if (s <= 15) {
    const std::int32_t half = std::int32_t{1} << (s - 1);
    for (int i = 0; i < n; ++i) out[i] = fixed::bounded::saturate_i16((g[i] + half - (g[i] < 0 ? 1 : 0)) >> s);
    return s;
  }
  const std::int64_t half = std::int64_t{1} << (s - 1);
  for (int i = 0; i < n; ++i) out[i] = fixed::saturate_i16((g[i] + half - (g[i] < 0 ? 1 : 0)) >> s);
  return s;
}

template <GeneratedModel M>
struct Numerics {
  using Value = typename M::Value;
  static constexpr bool kFixed = kIsFixed<M>;
  using Acc = std::conditional_t<kFixed, std::int64_t, float>;   // dot products
  using Grad = std::conditional_t<kFixed, std::int32_t, float>;  // controller gradients
  static_assert(std::is_same_v<Value, std::conditional_t<kFixed, std::int16_t, float>>,
                "Value must be int16_t (q15) or float (f32)");
  static_assert(std::is_same_v<typename M::Bias, std::conditional_t<kFixed, std::int32_t, float>>,
                "Bias must be int32_t (q15) or float (f32)");

  // sum_i a[i] * b[i] (q15: exact, in Q(fa + fb)).
  static constexpr Acc dot(const Value* a, const Value* b, int n) noexcept {
    if constexpr (kFixed) {
      return fixed::dot(a, b, n);
    } else {
      float acc = 0.0f;
      for (int i = 0; i < n; ++i) acc += a[i] * b[i];
      return acc;
    }
  }

  // Standardised real value -> Value in Q(Frac) (rounded, saturated).
  template <int Frac>
  static constexpr Value from_real(float v) noexcept {
    if constexpr (kFixed) {
      return fixed::to_q<Frac>(v);
    } else {
      return v;
    }
  }

  // Value in Q(Frac) -> real.
  template <int Frac>
  static constexpr float to_real(Value v) noexcept {
    if constexpr (kFixed) {
      return fixed::to_real<Frac, float>(v);
    } else {
      return v;
    }
  }

  // Accumulator in Q(FromFrac) -> Value in Q(ToFrac).
  template <int FromFrac, int ToFrac>
  static constexpr Value narrow(Acc acc) noexcept {
    if constexpr (kFixed) {
      return fixed::requantize_i16<FromFrac, ToFrac>(acc);
    } else {
      return acc;
    }
  }

  // Activations: input Q(kFracGate) = Q3.12, output Q15 (or float).
  static Value sigmoid(Value x) noexcept {
    if constexpr (kFixed) {
      return fixed::sigmoid_q15(x);
    } else {
      return 1.0f / (1.0f + std::exp(-x));
    }
  }
  static Value tanh(Value x) noexcept {
    if constexpr (kFixed) {
      return fixed::tanh_q15(x);
    } else {
      return std::tanh(x);
    }
  }

  // a * b with a in Q(AFrac), b in Q(BFrac) -> Q(YFrac).
  template <int AFrac, int BFrac, int YFrac>
  static constexpr Value mul(Value a, Value b) noexcept {
    if constexpr (kFixed) {
      return fixed::mul<AFrac, BFrac, YFrac>(a, b);
    } else {
      return a * b;
    }
  }

  // ---- gradients (controller backward pass)

  // g * a, g a gradient (common scale), a a Value in Q(AFrac): result at the
  // gradient scale, rounded and saturated to int32.
  template <int AFrac>
  static constexpr Grad grad_mul(Grad g, Value a) noexcept {
    if constexpr (kFixed) {
      return fixed::bounded::requantize_i32<AFrac, 0>(std::int64_t{g} * a);  // |g a| < 2^47
    } else {
      return g * a;
    }
  }
  // g * s with s a Q15 factor held in int32 (may be 1.0 = 32768).
  static constexpr Grad grad_mul_q15(Grad g, std::conditional_t<kFixed, std::int32_t, float> s) noexcept {
    if constexpr (kFixed) {
      return fixed::bounded::requantize_i32<15, 0>(std::int64_t{g} * s);  // |g s| <= 2^62
    } else {
      return g * s;
    }
  }
  static constexpr Grad grad_add(Grad a, Grad b) noexcept {
    if constexpr (kFixed) {
      return fixed::bounded::saturate_i32(std::int64_t{a} + b);  // fixed::add_sat32
    } else {
      return a + b;
    }
  }
  // sigma'(z) from the activated value s = sigma(z): s (1 - s), Q15 in int32.
  static constexpr auto sigmoid_slope(Value s) noexcept {
    if constexpr (kFixed) {
      // s (2^15 - s) is in [-2^31, 2^28] for every int16 s: exact in int32.
      const std::int32_t one = 1 << 15;
      return fixed::bounded::rounding_shift_right_i32<15>(std::int32_t{s} * (one - s));
    } else {
      return s * (1.0f - s);
    }
  }
  // tanh'(z) from t = tanh(z): 1 - t^2, Q15 in int32.
  static constexpr auto tanh_slope(Value t) noexcept {
    if constexpr (kFixed) {
      const std::int32_t one = 1 << 15;  // t^2 <= 2^30: exact in int32
      return one - fixed::bounded::rounding_shift_right_i32<15>(std::int32_t{t} * t);
    } else {
      return 1.0f - t * t;
    }
  }
  // Wide accumulator of gradient products (int64 / float).
  using GradAcc = std::conditional_t<kFixed, std::int64_t, float>;

  // f32: out[c] = sum_r w[r][c] * g[r] for c < n_cols (first columns of
  // W^T g). Row-wise (axpy) order so both w and g are read contiguously;
  // `scratch` holds n_cols accumulators. (q15 computes W^T g with
  // kernels::dot_cols_packed_q15 on the packed matrices, hadynet_net.h.)
  template <int WFrac, int Rows, int Cols>
  static constexpr void transposed_matvec(const Value (&w)[Rows][Cols], const Grad* g, int n_cols,
                                          Grad* out, GradAcc* scratch) noexcept
    requires(!kFixed)
  {
    for (int c = 0; c < n_cols; ++c) scratch[c] = 0;
    for (int r = 0; r < Rows; ++r) {
      const Grad gr = g[r];
      if (gr == 0) continue;  // same result, skips dead gates
      const Value* row = w[r];
      for (int c = 0; c < n_cols; ++c) scratch[c] += static_cast<GradAcc>(row[c]) * gr;
    }
    for (int c = 0; c < n_cols; ++c) out[c] = scratch[c];
  }
};

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_NUMERICS_H_
