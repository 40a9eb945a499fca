// The rounding and saturation of fixed_point.h in the form the hot loops of
// the q15 core need (the LSTM's element-wise step, the gate gradients of the
// backward pass, the gradients' block floating point): branch-free, with
// compile-time shifts, on a stated bounded domain. On that domain each
// function equals its fixed_point.h reference bit for bit
// (test/firmware/bounded_rounding_test.cc checks edges, ties and random
// values of every magnitude against the reference, the int16 forms on every
// input); outside it, it is not defined, so a caller
// states why its values stay inside.
//
// fixed_point.h stays the readable reference; these exist because its
// general forms (any int64, a run-time shift) cost the Cortex-M4 about twice
// the instructions (bench/qemu_icount.sh, docs/boards.md).
#ifndef HADYNET_FIRMWARE_CORE_BOUNDED_ROUNDING_H_
#define HADYNET_FIRMWARE_CORE_BOUNDED_ROUNDING_H_

#include <cstdint>

namespace hadynet::fixed::bounded {

// x / 2^Shift rounded half away from zero (= rounding_shift_right(x, Shift))
// for |x| <= 2^62: every product of two int32 and every exact sum of the
// core's products is in range. (x + half - [x < 0]) >> Shift: for x >= 0 the
// floor of x / 2^Shift + 1/2; for x < 0 a tie lands one below, away from zero.
template <int Shift>
[[nodiscard]] constexpr std::int64_t rounding_shift_right(std::int64_t x) noexcept {
  static_assert(Shift >= 1 && Shift <= 62, "shift out of range");
  return (x + (std::int64_t{1} << (Shift - 1)) - (x < 0 ? 1 : 0)) >> Shift;
}

// The same on int32 for x <= INT32_MAX - 2^(Shift - 1) (no overflow of the
// sum; every negative x is in range).
template <int Shift>
[[nodiscard]] constexpr std::int32_t rounding_shift_right_i32(std::int32_t x) noexcept {
  static_assert(Shift >= 1 && Shift <= 30, "shift out of range");
  return (x + (std::int32_t{1} << (Shift - 1)) - (x < 0 ? 1 : 0)) >> Shift;
}

// saturate_i32 of any int64: the value if its high word is the sign of its
// low word, else the rail of its sign.
[[nodiscard]] constexpr std::int32_t saturate_i32(std::int64_t x) noexcept {
  const auto low = static_cast<std::int32_t>(x);
  const auto high = static_cast<std::int32_t>(x >> 32);
  return high == (low >> 31) ? low : (high >> 31) ^ INT32_MAX;
}

// saturate_i16 of any int32.
[[nodiscard]] constexpr std::int16_t saturate_i16(std::int32_t x) noexcept {
  return static_cast<std::int16_t>(x < INT16_MIN ? INT16_MIN : (x > INT16_MAX ? INT16_MAX : x));
}

// requantize_i32<FromFrac, ToFrac> (FromFrac > ToFrac) for |acc| <= 2^62.
template <int FromFrac, int ToFrac>
[[nodiscard]] constexpr std::int32_t requantize_i32(std::int64_t acc) noexcept {
  static_assert(FromFrac > ToFrac, "a right shift");
  return saturate_i32(rounding_shift_right<FromFrac - ToFrac>(acc));
}

// requantize_i16<FromFrac, ToFrac> (FromFrac > ToFrac) for |acc| <= 2^62.
template <int FromFrac, int ToFrac>
[[nodiscard]] constexpr std::int16_t requantize_i16(std::int64_t acc) noexcept {
  static_assert(FromFrac > ToFrac, "a right shift");
  return saturate_i16(saturate_i32(rounding_shift_right<FromFrac - ToFrac>(acc)));
}

// requantize_i16<FromFrac, ToFrac> of an int16 value, in int32: a rounded
// right shift (never saturates) or a saturated left shift.
template <int FromFrac, int ToFrac>
[[nodiscard]] constexpr std::int16_t rescale_i16(std::int16_t v) noexcept {
  static_assert(FromFrac - ToFrac <= 15 && ToFrac - FromFrac <= 15, "shift out of range");
  if constexpr (FromFrac > ToFrac) {
    return static_cast<std::int16_t>(rounding_shift_right_i32<FromFrac - ToFrac>(v));
  } else {
    return saturate_i16(std::int32_t{v} * (std::int32_t{1} << (ToFrac - FromFrac)));
  }
}

// mul<AFrac, BFrac, YFrac> (AFrac + BFrac > YFrac): the int16 product is
// exact in int32 and |a b| + 2^29 < 2^31.
template <int AFrac, int BFrac, int YFrac>
[[nodiscard]] constexpr std::int16_t mul(std::int16_t a, std::int16_t b) noexcept {
  static_assert(AFrac + BFrac - YFrac >= 1 && AFrac + BFrac - YFrac <= 30, "shift out of range");
  return saturate_i16(rounding_shift_right_i32<AFrac + BFrac - YFrac>(std::int32_t{a} * b));
}

// The LSTM's cell update c' = f c + i g of int16 Q15 gates f, i, g and a
// Q(C) cell c: requantize_i16<30 + C, C>(f c 2^15 + i g 2^C), any int16
// inputs. For C < 15 in int32: with k = 15 - C the exact sum is
// 2^C (2^k a + r), a = f c + (i g >> k), r = i g mod 2^k, and
// round((2^k a + r) / 2^(15 + k)) half away from zero is
// (a + 2^14 - [a < 0 and r = 0]) >> 15 (the sum is negative exactly when a
// is; a tie of a negative sum has r = 0 and a one below). |a| <= 1.5 2^30.
template <int C>
[[nodiscard]] constexpr std::int16_t cell_update(std::int16_t f, std::int16_t c, std::int16_t i,
                                                 std::int16_t g) noexcept {
  static_assert(C >= 0 && C <= 15, "c is int16");
  if constexpr (C == 15) {
    return requantize_i16<45, 15>(std::int64_t{std::int32_t{f} * c} * 32768 + std::int64_t{std::int32_t{i} * g} * 32768);
  } else {
    constexpr int k = 15 - C;
    const std::int32_t ig = std::int32_t{i} * g;
    const std::int32_t a = std::int32_t{f} * c + (ig >> k);
    const std::int32_t tie_down = (a < 0 && (ig & ((std::int32_t{1} << k) - 1)) == 0) ? 1 : 0;
    return saturate_i16((a + (std::int32_t{1} << 14) - tie_down) >> 15);
  }
}

}  // namespace hadynet::fixed::bounded

#endif  // HADYNET_FIRMWARE_CORE_BOUNDED_ROUNDING_H_
