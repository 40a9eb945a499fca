// Tests for firmware/core/fixed_point.h against independent int64 / double
// references written here (never against the code under test).
//
// Tolerances (one place, stated once):
//  * Integer ops (saturation, add/sub, mac, rounding shifts, requantise, mul,
//    dot): exact, 0 LSB. The references compute the same mathematically
//    defined result (round half away from zero, then clamp) by a different
//    route: int64 division/remainder, overflow builtins, or double arithmetic
//    on values that double represents exactly (< 2^53).
//  * matvec with integer inputs vs the exact double result: |error| <= 0.5 LSB
//    of the output format, because the int64 row sum is exact and the only
//    rounding is the final requantise; ties must go away from zero, so we also
//    require equality with std::round of the exact value.
//  * matvec of a float model quantised with to_q vs the double model:
//    0.5 LSB_y (output rounding) + sum_c (|x_c| e_w + |w_c| e_x + e_w e_x)
//    + e_b, with e_w = 0.5 LSB_w, e_x = 0.5 LSB_x, e_b = 0.5 LSB_acc: the
//    first-order error of rounding each operand to nearest, plus the
//    product of the two rounding errors. A 1e-9 slack covers double rounding
//    of the reference sum itself.
#include "firmware/core/fixed_point.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace hf = hadynet::fixed;

namespace {

constexpr std::int64_t kI16Min = std::numeric_limits<std::int16_t>::min();
constexpr std::int64_t kI16Max = std::numeric_limits<std::int16_t>::max();
constexpr std::int64_t kI32Min = std::numeric_limits<std::int32_t>::min();
constexpr std::int64_t kI32Max = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t kI64Min = std::numeric_limits<std::int64_t>::min();
constexpr std::int64_t kI64Max = std::numeric_limits<std::int64_t>::max();

std::int64_t clamp64(std::int64_t v, std::int64_t lo, std::int64_t hi) { return std::min(std::max(v, lo), hi); }

double clamp_d(double v, double lo, double hi) { return std::min(std::max(v, lo), hi); }

// Reference: x * 2^(to - from), rounded half away from zero / saturated to
// int64, via truncating division and remainder (not shifts).
std::int64_t ref_rescale(std::int64_t x, int from, int to) {
  if (from >= to) {
    const int s = from - to;
    if (s == 0) {
      return x;
    }
    const std::int64_t d = std::int64_t{1} << s;
    std::int64_t q = x / d;                     // toward zero
    const std::int64_t r = x % d;               // same sign as x, |r| < d
    const std::int64_t abs_r = r < 0 ? -r : r;  // |r| < 2^62: no overflow
    if (2 * abs_r >= d) {
      q += x < 0 ? -1 : 1;  // away from zero at and above the half
    }
    return q;
  }
  std::int64_t out = 0;
  if (__builtin_mul_overflow(x, std::int64_t{1} << (to - from), &out)) {
    return x < 0 ? kI64Min : kI64Max;
  }
  return out;
}

// Fixed, seeded generator: tests are deterministic.
std::mt19937_64& rng() {
  static std::mt19937_64 gen(0x4841'4459'4E45'54ULL);
  return gen;
}

std::int16_t random_i16() {
  return static_cast<std::int16_t>(std::uniform_int_distribution<int>(kI16Min, kI16Max)(rng()));
}

// A set of int16 operands: a stride over the whole range plus the extremes
// and the neighbourhood of zero.
std::vector<std::int16_t> dense_i16_operands() {
  std::vector<std::int16_t> v;
  for (std::int32_t x = kI16Min; x <= kI16Max; x += 61) {
    v.push_back(static_cast<std::int16_t>(x));
  }
  for (std::int32_t x : {-32768, -32767, -32766, -16384, -2, -1, 0, 1, 2, 16384, 32766, 32767}) {
    v.push_back(static_cast<std::int16_t>(x));
  }
  return v;
}

// int64 test values: a dense block around zero, every power of two and its
// neighbours (both signs), the int16/int32 saturation boundaries at every
// scale, the int64 extremes, and random values of random magnitude.
std::vector<std::int64_t> int64_sweep() {
  std::vector<std::int64_t> v;
  for (std::int64_t x = -5000; x <= 5000; ++x) {
    v.push_back(x);
  }
  for (int s = 0; s <= 62; ++s) {
    const std::int64_t p = std::int64_t{1} << s;
    for (std::int64_t d = -3; d <= 3; ++d) {
      v.push_back(p + d);
      v.push_back(-p + d);
      if (s >= 1 && s <= 47) {
        v.push_back(kI16Max * p + d);
        v.push_back(kI16Min * p + d);
        v.push_back(kI16Max * p + p / 2 + d);  // around the x.5 tie
        v.push_back(kI16Min * p - p / 2 + d);
      }
      if (s <= 31) {
        v.push_back(kI32Max * p + d);
        v.push_back(kI32Min * p + d);
      }
    }
  }
  for (std::int64_t d = 0; d <= 3; ++d) {
    v.push_back(kI64Max - d);
    v.push_back(kI64Min + d);
  }
  std::uniform_int_distribution<int> bits(1, 63);
  for (int i = 0; i < 20000; ++i) {
    const std::int64_t raw = static_cast<std::int64_t>(rng()());
    v.push_back(raw >> (64 - bits(rng())));  // random magnitude, both signs
  }
  return v;
}

// ---------------------------------------------------------------------------
// Compile-time evaluation
// ---------------------------------------------------------------------------

static_assert(hf::saturate_i16(std::int32_t{40000}) == 32767);
static_assert(hf::saturate_i16(std::int64_t{-40000}) == -32768);
static_assert(hf::saturate_i32(kI64Max) == kI32Max);
static_assert(hf::add_sat(32767, 1) == 32767);
static_assert(hf::sub_sat(-32768, 1) == -32768);
static_assert(hf::add_sat32(static_cast<std::int32_t>(kI32Max), 1) == kI32Max);
static_assert(hf::mac(10, -32768, -32768) == (std::int64_t{1} << 30) + 10);
static_assert(hf::mac_sat32(static_cast<std::int32_t>(kI32Max), 2, 3) == kI32Max);
static_assert(hf::rounding_shift_right(5, 1) == 3);
static_assert(hf::rounding_shift_right(-5, 1) == -3);
static_assert(hf::rounding_shift_right(kI64Min, 62) == -2);
static_assert(hf::saturating_shift_left(kI64Max / 2 + 1, 1) == kI64Max);
static_assert(hf::requantize_i16<30, 15>(std::int64_t{1} << 30) == 32767);  // 1.0 in Q15 saturates
static_assert(hf::requantize_i16<4, 8>(3) == 48);
static_assert(hf::mul<15, 15, 15>(-32768, -32768) == 32767);
static_assert(hf::mul<15, 11, 11>(16384, 4096) == 2048);  // 0.5 * 2.0 = 1.0
static_assert(hf::to_q<15>(0.5f) == 16384);
static_assert(hf::to_q<15>(-1.0) == -32768);
static_assert(hf::to_q<0>(2.5) == 3 && hf::to_q<0>(-2.5) == -3);
static_assert(hf::to_real<8>(std::int16_t{384}) == 1.5f);
static_assert(hf::real_to_fixed<std::int32_t, 23>(1.0e9) == kI32Max);
static_assert(hf::QFormat<12>::int_bits == 3 && hf::QFormat<12>::raw_one == 4096);
static_assert(hf::QFormat<15>::raw_one == 32767);

constexpr std::int16_t kConstA[4] = {32767, -32768, 1000, -3};
constexpr std::int16_t kConstB[4] = {32767, -32768, 100, 7};
constexpr std::int16_t kConstC[4] = {32767, -32768, -1000, -3};
static_assert(hf::dot(kConstA, kConstB) == 32767LL * 32767 + 32768LL * 32768 + 100000 - 21);
static_assert(hf::dot_q15(kConstA, kConstB) == kI32Max);  // exact sum is 2^31 + 34445
static_assert(hf::dot_q15(kConstC, kConstB) == 32767LL * 32767 + 32768LL * 32768 - 100000 - 21);

// A whole matvec in a constant expression: W Q8, x Q8, bias Q16, y Q8.
constexpr std::array<std::int16_t, 2> constexpr_matvec() {
  const std::int16_t w[2][3] = {{256, 512, -256}, {32767, 32767, 32767}};  // {1, 2, -1}, {~128 x3}
  const std::int16_t x[3] = {128, 64, 256};                                // {0.5, 0.25, 1}
  const std::int32_t bias[2] = {1 << 16, 0};                               // {1, 0}
  std::int16_t y[2] = {};
  hf::matvec<8, 8, 8>(w, x, bias, y);
  return {y[0], y[1]};
}
static_assert(constexpr_matvec()[0] == 256);    // 1 + 0.5 + 0.5 - 1 = 1.0
static_assert(constexpr_matvec()[1] == 32767);  // ~224: saturates

static_assert(noexcept(hf::add_sat(0, 0)));
static_assert(noexcept(hf::requantize_i16<20, 10>(0)));
static_assert(noexcept(hf::dot(kConstA, kConstB)));

// ---------------------------------------------------------------------------
// Saturating narrowing
// ---------------------------------------------------------------------------

TEST(FixedPointSaturate, Int32ToInt16DenseSweepClampsNeverWraps) {
  std::int64_t mismatches = 0;
  for (std::int32_t x = -200000; x <= 200000; ++x) {
    mismatches += hf::saturate_i16(x) != clamp64(x, kI16Min, kI16Max);
  }
  const std::int64_t extremes[] = {kI32Min, kI32Min + 1, kI32Max - 1, kI32Max, -65536, 65535, 65536};
  for (std::int64_t x : extremes) {
    const auto x32 = static_cast<std::int32_t>(x);
    mismatches += hf::saturate_i16(x32) != clamp64(x, kI16Min, kI16Max);
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(FixedPointSaturate, Int64ToInt16AndInt32) {
  std::int64_t mismatches = 0;
  for (std::int64_t x : int64_sweep()) {
    mismatches += hf::saturate_i16(x) != clamp64(x, kI16Min, kI16Max);
    mismatches += hf::saturate_i32(x) != clamp64(x, kI32Min, kI32Max);
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(hf::saturate_i16(kI64Min), kI16Min);
  EXPECT_EQ(hf::saturate_i16(kI64Max), kI16Max);
  EXPECT_EQ(hf::saturate_i32(kI64Min), kI32Min);
  EXPECT_EQ(hf::saturate_i32(kI32Max + 1), kI32Max);
}

// ---------------------------------------------------------------------------
// Saturating add / sub
// ---------------------------------------------------------------------------

TEST(FixedPointAddSub, Int16AllAAgainstDenseBSaturates) {
  const std::vector<std::int16_t> bs = dense_i16_operands();
  std::int64_t mismatches = 0;
  for (std::int32_t ai = kI16Min; ai <= kI16Max; ++ai) {
    const auto a = static_cast<std::int16_t>(ai);
    for (std::int16_t b : bs) {
      mismatches += hf::add_sat(a, b) != clamp64(std::int64_t{a} + b, kI16Min, kI16Max);
      mismatches += hf::sub_sat(a, b) != clamp64(std::int64_t{a} - b, kI16Min, kI16Max);
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(hf::add_sat(32767, 32767), 32767);
  EXPECT_EQ(hf::add_sat(-32768, -32768), -32768);
  EXPECT_EQ(hf::sub_sat(0, -32768), 32767);  // -(-32768) does not wrap
  EXPECT_EQ(hf::sub_sat(-1, 32767), -32768);
}

TEST(FixedPointAddSub, Int32NearExtremes) {
  std::vector<std::int64_t> xs;
  for (std::int64_t d = -3; d <= 3; ++d) {
    const std::int64_t bases[] = {kI32Min + 3, kI32Max - 3, 0, kI32Max / 2, kI32Min / 2};
    for (std::int64_t base : bases) {
      xs.push_back(base + d);
    }
  }
  std::int64_t mismatches = 0;
  for (std::int64_t a : xs) {
    for (std::int64_t b : xs) {
      const auto a32 = static_cast<std::int32_t>(a);
      const auto b32 = static_cast<std::int32_t>(b);
      mismatches += hf::add_sat32(a32, b32) != clamp64(a + b, kI32Min, kI32Max);
      mismatches += hf::sub_sat32(a32, b32) != clamp64(a - b, kI32Min, kI32Max);
    }
  }
  EXPECT_EQ(mismatches, 0);
}

// ---------------------------------------------------------------------------
// Multiply-accumulate
// ---------------------------------------------------------------------------

TEST(FixedPointMac, ExactAndSaturatingInt32) {
  const std::vector<std::int16_t> ops = dense_i16_operands();
  const std::int64_t accs[] = {0, 1, -1, kI32Max, kI32Min, kI32Max - (1LL << 30), kI32Min + (1LL << 30), 123456789};
  std::int64_t mismatches = 0;
  for (std::int16_t a : ops) {
    for (std::int16_t b : ops) {
      const std::int64_t p = std::int64_t{a} * std::int64_t{b};
      for (std::int64_t acc : accs) {
        mismatches += hf::mac(acc, a, b) != acc + p;
        mismatches += hf::mac_sat32(static_cast<std::int32_t>(acc), a, b) != clamp64(acc + p, kI32Min, kI32Max);
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
}

// ---------------------------------------------------------------------------
// Rounding: ties away from zero
// ---------------------------------------------------------------------------

TEST(FixedPointRounding, TiesGoAwayFromZero) {
  // shift 1: x / 2
  EXPECT_EQ(hf::rounding_shift_right(1, 1), 1);    //  0.5  ->  1
  EXPECT_EQ(hf::rounding_shift_right(-1, 1), -1);  // -0.5  -> -1
  EXPECT_EQ(hf::rounding_shift_right(3, 1), 2);    //  1.5  ->  2
  EXPECT_EQ(hf::rounding_shift_right(-3, 1), -2);  // -1.5  -> -2
  EXPECT_EQ(hf::rounding_shift_right(5, 1), 3);    //  2.5  ->  3 (not 2: not ties-to-even)
  EXPECT_EQ(hf::rounding_shift_right(-5, 1), -3);  // -2.5  -> -3
  // shift 2: x / 4
  EXPECT_EQ(hf::rounding_shift_right(1, 2), 0);    //  0.25 ->  0
  EXPECT_EQ(hf::rounding_shift_right(-1, 2), 0);   // -0.25 ->  0
  EXPECT_EQ(hf::rounding_shift_right(2, 2), 1);    //  0.5  ->  1
  EXPECT_EQ(hf::rounding_shift_right(-2, 2), -1);  // -0.5  -> -1
  EXPECT_EQ(hf::rounding_shift_right(3, 2), 1);    //  0.75 ->  1
  EXPECT_EQ(hf::rounding_shift_right(-3, 2), -1);  // -0.75 -> -1
  EXPECT_EQ(hf::rounding_shift_right(-6, 2), -2);  // -1.5  -> -2
  // Every tie (2k+1) * 2^(s-1) for s = 1..16 and |k| < 4096.
  std::int64_t mismatches = 0;
  for (int s = 1; s <= 16; ++s) {
    for (std::int64_t k = -4096; k < 4096; ++k) {
      const std::int64_t x = (2 * k + 1) * (std::int64_t{1} << (s - 1));
      const std::int64_t expected = k >= 0 ? k + 1 : k;  // (k + 0.5) away from zero
      mismatches += hf::rounding_shift_right(x, s) != expected;
    }
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(FixedPointRounding, RoundingShiftRightMatchesReference) {
  std::int64_t mismatches = 0;
  for (int s = 1; s <= 16; ++s) {
    for (std::int64_t x = -(1 << 18); x <= (1 << 18); ++x) {
      mismatches += hf::rounding_shift_right(x, s) != ref_rescale(x, s, 0);
      // double reference: x and x / 2^s are exact in double; std::round is
      // half away from zero.
      mismatches += hf::rounding_shift_right(x, s) != static_cast<std::int64_t>(std::round(std::ldexp(static_cast<double>(x), -s)));
    }
  }
  const std::vector<std::int64_t> xs = int64_sweep();
  for (int s = 0; s <= 62; ++s) {
    for (std::int64_t x : xs) {
      mismatches += hf::rounding_shift_right(x, s) != ref_rescale(x, s, 0);
      mismatches += hf::saturating_shift_left(x, s) != ref_rescale(x, 0, s);
    }
  }
  EXPECT_EQ(mismatches, 0);
}

// ---------------------------------------------------------------------------
// Requantisation across formats
// ---------------------------------------------------------------------------

template <int From, int To>
std::int64_t requantize_mismatches(const std::vector<std::int64_t>& xs) {
  std::int64_t mismatches = 0;
  for (std::int64_t x : xs) {
    const std::int64_t exact = ref_rescale(x, From, To);
    mismatches += hf::rescale<From, To>(x) != exact;
    mismatches += hf::requantize_i16<From, To>(x) != clamp64(exact, kI16Min, kI16Max);
    mismatches += hf::requantize_i32<From, To>(x) != clamp64(exact, kI32Min, kI32Max);
    if (x > -(std::int64_t{1} << 53) && x < (std::int64_t{1} << 53)) {
      // Independent double route: x * 2^(To-From) is exact in double here.
      const double real = std::round(std::ldexp(static_cast<double>(x), To - From));
      const double expected = clamp_d(real, static_cast<double>(kI16Min), static_cast<double>(kI16Max));
      mismatches += static_cast<double>(hf::requantize_i16<From, To>(x)) != expected;
    }
  }
  return mismatches;
}

template <int From, int... Tos>
std::int64_t requantize_mismatches_from(std::integer_sequence<int, Tos...>, const std::vector<std::int64_t>& xs) {
  return (requantize_mismatches<From, Tos>(xs) + ...);
}

template <int... Froms>
std::int64_t requantize_mismatches_all(std::integer_sequence<int, Froms...>, const std::vector<std::int64_t>& xs) {
  return (requantize_mismatches_from<Froms>(std::make_integer_sequence<int, 16>{}, xs) + ...);
}

// Every source format Q0..Q31 (accumulators of Q(a+b) with a, b <= 15 reach
// Q30) to every int16 destination Q0..Q15, dense and random values.
TEST(FixedPointRequantize, AllFormatPairsMatchReference) {
  const std::vector<std::int64_t> xs = int64_sweep();
  EXPECT_EQ(requantize_mismatches_all(std::make_integer_sequence<int, 32>{}, xs), 0);
}

TEST(FixedPointRequantize, SaturatesAtInt16Extremes) {
  // Q23 accumulator -> Q11: one output LSB is 2^12 accumulator LSBs.
  constexpr std::int64_t lsb = std::int64_t{1} << 12;
  EXPECT_EQ((hf::requantize_i16<23, 11>(kI16Max * lsb)), 32767);
  EXPECT_EQ((hf::requantize_i16<23, 11>(kI16Max * lsb + lsb / 2 - 1)), 32767);
  EXPECT_EQ((hf::requantize_i16<23, 11>(kI16Max * lsb + lsb / 2)), 32767);  // 32767.5 -> 32768 -> sat
  EXPECT_EQ((hf::requantize_i16<23, 11>(kI64Max)), 32767);
  EXPECT_EQ((hf::requantize_i16<23, 11>(kI16Min * lsb)), -32768);
  EXPECT_EQ((hf::requantize_i16<23, 11>(kI16Min * lsb - lsb / 2)), -32768);  // -32768.5 -> sat
  EXPECT_EQ((hf::requantize_i16<23, 11>(kI64Min)), -32768);
  // Adding fractional bits saturates instead of wrapping.
  EXPECT_EQ((hf::requantize_i16<0, 15>(1)), 32767);
  EXPECT_EQ((hf::requantize_i16<0, 15>(-1)), -32768);
  EXPECT_EQ((hf::requantize_i16<0, 15>(kI64Min)), -32768);
  EXPECT_EQ((hf::rescale<0, 62>(1)), std::int64_t{1} << 62);
  EXPECT_EQ((hf::rescale<0, 62>(2)), kI64Max);   // 2^63 does not fit: saturates
  EXPECT_EQ((hf::rescale<0, 62>(-2)), kI64Min);  // -2^63 fits exactly
  EXPECT_EQ((hf::rescale<0, 62>(-3)), kI64Min);  // saturates
}

TEST(FixedPointMul, ElementwiseMatchesDoubleReference) {
  const std::vector<std::int16_t> bs = dense_i16_operands();
  std::int64_t mismatches = 0;
  auto check = [&](auto mul, int af, int bf, int yf) {
    for (std::int32_t ai = kI16Min; ai <= kI16Max; ai += 7) {
      for (std::int16_t b : bs) {
        const auto a = static_cast<std::int16_t>(ai);
        const double exact = std::ldexp(static_cast<double>(a) * b, yf - af - bf);  // exact in double
        const double expected = clamp_d(std::round(exact), static_cast<double>(kI16Min), static_cast<double>(kI16Max));
        mismatches += static_cast<double>(mul(a, b)) != expected;
      }
    }
  };
  check([](std::int16_t a, std::int16_t b) { return hf::mul<15, 11, 11>(a, b); }, 15, 11, 11);
  check([](std::int16_t a, std::int16_t b) { return hf::mul<15, 15, 15>(a, b); }, 15, 15, 15);
  check([](std::int16_t a, std::int16_t b) { return hf::mul<8, 8, 12>(a, b); }, 8, 8, 12);
  check([](std::int16_t a, std::int16_t b) { return hf::mul<0, 0, 0>(a, b); }, 0, 0, 0);
  EXPECT_EQ(mismatches, 0);
}

// ---------------------------------------------------------------------------
// Real <-> Q conversion
// ---------------------------------------------------------------------------

template <int F>
std::int64_t conversion_mismatches() {
  std::int64_t mismatches = 0;
  const double lsb = std::ldexp(1.0, -F);
  for (std::int32_t qi = kI16Min; qi <= kI16Max; ++qi) {
    const auto q = static_cast<std::int16_t>(qi);
    // Round trip is exact in float and double.
    mismatches += hf::to_q<F>(hf::to_real<F, float>(q)) != q;
    mismatches += hf::to_q<F>(hf::to_real<F, double>(q)) != q;
    mismatches += hf::to_real<F, double>(q) != static_cast<double>(q) * lsb;
    // Ties (q +- 0.5 LSB, exact in float: 17 significant bits) go away from
    // zero, and saturate past the extremes.
    const float up = static_cast<float>((qi + 0.5) * lsb);
    const float down = static_cast<float>((qi - 0.5) * lsb);
    const std::int64_t up_expected = qi >= 0 ? clamp64(qi + 1, kI16Min, kI16Max) : qi;
    const std::int64_t down_expected = qi <= 0 ? clamp64(qi - 1, kI16Min, kI16Max) : qi;
    mismatches += hf::to_q<F>(up) != up_expected;
    mismatches += hf::to_q<F>(down) != down_expected;
    // Just inside the half: nearest is q.
    mismatches += hf::to_q<F>((qi + 0.49) * lsb) != q;
    mismatches += hf::to_q<F>((qi - 0.49) * lsb) != q;
  }
  // Random reals over twice the representable range vs std::round + clamp.
  std::uniform_real_distribution<double> dist(-2.0 * 32768.0 * lsb, 2.0 * 32768.0 * lsb);
  for (int i = 0; i < 20000; ++i) {
    const double r = dist(rng());
    const double expected = clamp_d(std::round(std::ldexp(r, F)), static_cast<double>(kI16Min), static_cast<double>(kI16Max));
    mismatches += static_cast<double>(hf::to_q<F>(r)) != expected;
  }
  return mismatches;
}

TEST(FixedPointConversion, RoundTripTiesAndSaturationAllFormats) {
  EXPECT_EQ(conversion_mismatches<0>(), 0);
  EXPECT_EQ(conversion_mismatches<1>(), 0);
  EXPECT_EQ(conversion_mismatches<7>(), 0);
  EXPECT_EQ(conversion_mismatches<8>(), 0);
  EXPECT_EQ(conversion_mismatches<11>(), 0);
  EXPECT_EQ(conversion_mismatches<12>(), 0);
  EXPECT_EQ(conversion_mismatches<14>(), 0);
  EXPECT_EQ(conversion_mismatches<15>(), 0);
}

TEST(FixedPointConversion, NonFiniteAndHugeValues) {
  constexpr float inf = std::numeric_limits<float>::infinity();
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(hf::to_q<11>(inf), 32767);
  EXPECT_EQ(hf::to_q<11>(-inf), -32768);
  EXPECT_EQ(hf::to_q<11>(nan), 0);
  EXPECT_EQ(hf::to_q<11>(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(hf::to_q<0>(1.0e30f), 32767);
  EXPECT_EQ(hf::to_q<15>(-1.0e300), -32768);
  EXPECT_EQ(hf::to_q<15>(1.0f), 32767);  // 1.0 is not representable in Q15
  EXPECT_EQ(hf::to_q<15>(-1.0f), -32768);
  EXPECT_EQ(hf::to_q<15>(std::numeric_limits<float>::denorm_min()), 0);
  EXPECT_EQ((hf::real_to_fixed<std::int32_t, 23>(256.0)), kI32Max);     // 2^31 saturates
  EXPECT_EQ((hf::real_to_fixed<std::int32_t, 23>(-256.0)), kI32Min);    // -2^31 fits
  EXPECT_EQ((hf::real_to_fixed<std::int32_t, 0>(2147483647.5)), kI32Max);  // tie rounds up, saturates
  EXPECT_EQ((hf::real_to_fixed<std::int32_t, 0>(-2147483648.5)), kI32Min);
  EXPECT_EQ((hf::real_to_fixed<std::int64_t, 0>(1.0e19)), kI64Max);
  EXPECT_EQ((hf::real_to_fixed<std::int64_t, 0>(-1.0e19)), kI64Min);
}

// ---------------------------------------------------------------------------
// Dot product and matrix-vector kernels
// ---------------------------------------------------------------------------

TEST(FixedPointDot, MatchesExactDoubleReference) {
  // Products are <= 2^30 and 144 of them sum below 2^38 < 2^53, so the double
  // reference is exact: tolerance 0.
  constexpr int n = 144;
  std::int16_t a[n];
  std::int16_t b[n];
  for (int trial = 0; trial < 2000; ++trial) {
    double expected = 0.0;
    for (int i = 0; i < n; ++i) {
      a[i] = random_i16();
      b[i] = random_i16();
      expected += static_cast<double>(a[i]) * static_cast<double>(b[i]);
    }
    ASSERT_EQ(static_cast<double>(hf::dot(a, b)), expected);
    ASSERT_EQ(hf::dot(a, b), hf::dot(&a[0], &b[0], n));
    ASSERT_EQ(hf::dot_q15(a, b), hf::dot_q15(&a[0], &b[0], n));
    ASSERT_EQ(static_cast<double>(hf::dot_q15(a, b)), clamp_d(expected, static_cast<double>(kI32Min), static_cast<double>(kI32Max)));
  }
}

TEST(FixedPointDot, ExtremesDoNotOverflowAndQ15Saturates) {
  constexpr int n = 512;
  std::int16_t min_v[n];
  std::int16_t max_v[n];
  std::fill(std::begin(min_v), std::end(min_v), static_cast<std::int16_t>(kI16Min));
  std::fill(std::begin(max_v), std::end(max_v), static_cast<std::int16_t>(kI16Max));
  EXPECT_EQ(hf::dot(min_v, min_v), n * (std::int64_t{1} << 30));
  EXPECT_EQ(hf::dot(min_v, max_v), -n * 32768LL * 32767LL);
  EXPECT_EQ(hf::dot_q15(min_v, min_v), kI32Max);  // real sum 512.0 leaves [-2, 2)
  EXPECT_EQ(hf::dot_q15(min_v, max_v), kI32Min);
  EXPECT_EQ(hf::dot(&min_v[0], &max_v[0], 0), 0);
  EXPECT_EQ(hf::dot(&min_v[0], &max_v[0], -3), 0);
}

// Exact real value of row r of W x + b, in units of 2^-(wf + xf) (integer
// valued and < 2^53, so exact in double).
template <int Rows, int Cols>
double exact_row_acc(const std::int16_t (&w)[Rows][Cols], const std::int16_t (&x)[Cols], const std::int32_t (&bias)[Rows], int r) {
  double acc = static_cast<double>(bias[r]);
  for (int c = 0; c < Cols; ++c) {
    acc += static_cast<double>(w[r][c]) * static_cast<double>(x[c]);
  }
  return acc;
}

template <int WF, int XF, int YF, int Rows, int Cols>
void check_integer_matvec(int trials, int operand_range) {
  static std::int16_t w[Rows][Cols];  // static: no large arrays on the stack
  static std::int16_t x[Cols];
  static std::int32_t bias[Rows];
  static std::int16_t y[Rows];
  std::uniform_int_distribution<int> op(-operand_range, operand_range);
  std::uniform_int_distribution<std::int32_t> bias_dist(-(1 << 26), 1 << 26);
  for (int t = 0; t < trials; ++t) {
    for (auto& row : w) {
      for (auto& v : row) {
        v = static_cast<std::int16_t>(op(rng()));
      }
    }
    for (auto& v : x) {
      v = static_cast<std::int16_t>(op(rng()));
    }
    for (auto& v : bias) {
      v = bias_dist(rng());
    }
    hf::matvec<WF, XF, YF>(w, x, bias, y);
    for (int r = 0; r < Rows; ++r) {
      const double in_y_lsb = std::ldexp(exact_row_acc(w, x, bias, r), YF - WF - XF);
      const double lo = static_cast<double>(kI16Min);
      const double hi = static_cast<double>(kI16Max);
      // 0.5 LSB bound (single rounding) ...
      ASSERT_LE(std::fabs(static_cast<double>(y[r]) - clamp_d(in_y_lsb, lo, hi)), 0.5) << "row " << r;
      // ... and exactly the half-away-from-zero result.
      ASSERT_EQ(static_cast<double>(y[r]), clamp_d(std::round(in_y_lsb), lo, hi)) << "row " << r;
    }
  }
}

TEST(FixedPointMatvec, IntegerInputsWithinHalfLsbOfExact) {
  // Small operands: no saturation, rounding dominates.
  check_integer_matvec<12, 11, 11, 128, 45>(50, 3000);
  check_integer_matvec<12, 11, 8, 27, 128>(50, 3000);
  check_integer_matvec<15, 15, 15, 16, 16>(200, 2000);
  // Full-range operands: most outputs saturate.
  check_integer_matvec<12, 11, 11, 128, 45>(20, 32767);
  check_integer_matvec<4, 4, 12, 64, 8>(50, 32767);  // adds fractional bits
}

TEST(FixedPointMatvec, SaturatesRowsAtInt16Extremes) {
  const std::int16_t w[3][2] = {{32767, 32767}, {-32768, -32768}, {-32768, 32767}};
  const std::int16_t x[2] = {32767, 32767};
  const std::int32_t bias[3] = {0, 0, 0};
  std::int16_t y[3] = {};
  hf::matvec<15, 15, 15>(w, x, bias, y);
  EXPECT_EQ(y[0], 32767);   // ~ +2.0
  EXPECT_EQ(y[1], -32768);  // ~ -2.0
  EXPECT_EQ(y[2], -1);      // (-32768 + 32767) * 32767 / 2^15 = -0.99997 LSB -> -1
}

TEST(FixedPointMatvec, AccumulateEqualsConcatenatedMatrix) {
  // W_ih [u;p] + W_hh h summed exactly == [W_ih W_hh] [u;p;h].
  constexpr int rows = 32;
  constexpr int n1 = 16;
  constexpr int n2 = 24;
  static std::int16_t w1[rows][n1];
  static std::int16_t w2[rows][n2];
  static std::int16_t wc[rows][n1 + n2];
  std::int16_t x1[n1];
  std::int16_t x2[n2];
  std::int16_t xc[n1 + n2];
  std::int32_t bias[rows];
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < n1; ++c) {
      wc[r][c] = w1[r][c] = random_i16();
    }
    for (int c = 0; c < n2; ++c) {
      wc[r][n1 + c] = w2[r][c] = random_i16();
    }
    bias[r] = static_cast<std::int32_t>(std::uniform_int_distribution<std::int64_t>(kI32Min, kI32Max)(rng()));
  }
  for (int c = 0; c < n1; ++c) {
    xc[c] = x1[c] = random_i16();
  }
  for (int c = 0; c < n2; ++c) {
    xc[n1 + c] = x2[c] = random_i16();
  }
  hf::Accumulator acc[rows];
  for (int r = 0; r < rows; ++r) {
    acc[r] = bias[r];
  }
  hf::matvec_accumulate(w1, x1, acc);
  hf::matvec_accumulate(w2, x2, acc);
  std::int16_t y_split[rows];
  std::int16_t y_concat[rows];
  for (int r = 0; r < rows; ++r) {
    y_split[r] = hf::requantize_i16<26, 10>(acc[r]);
  }
  hf::matvec<13, 13, 10>(wc, xc, bias, y_concat);
  for (int r = 0; r < rows; ++r) {
    EXPECT_EQ(acc[r], bias[r] + hf::dot(wc[r], xc)) << "row " << r;
    EXPECT_EQ(y_split[r], y_concat[r]) << "row " << r;
  }
}

TEST(FixedPointMatvec, QuantisedFloatModelWithinStatedBound) {
  // Real model: W in [-0.5, 0.5) (Q12), x in [-2, 2) (Q11), b in [-1, 1]
  // (accumulator Q23), y in Q8 (range +-128, |y| <= 45 * 1 + 1 = 46: no
  // saturation). Bound: see the file header.
  constexpr int WF = 12;
  constexpr int XF = 11;
  constexpr int YF = 8;
  constexpr int rows = 128;
  constexpr int cols = 45;
  static double w_real[rows][cols];
  static std::int16_t w[rows][cols];
  double x_real[cols];
  double b_real[rows];
  std::int16_t x[cols];
  std::int32_t bias[rows];
  std::int16_t y[rows];
  std::uniform_real_distribution<double> wd(-0.5, 0.5);
  std::uniform_real_distribution<double> xd(-2.0, 2.0);
  std::uniform_real_distribution<double> bd(-1.0, 1.0);
  const double e_w = 0.5 * std::ldexp(1.0, -WF);
  const double e_x = 0.5 * std::ldexp(1.0, -XF);
  const double e_b = 0.5 * std::ldexp(1.0, -(WF + XF));
  const double e_y = 0.5 * std::ldexp(1.0, -YF);
  double worst_ratio = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        w_real[r][c] = wd(rng());
        w[r][c] = hf::to_q<WF>(w_real[r][c]);
      }
      b_real[r] = bd(rng());
      bias[r] = hf::real_to_fixed<std::int32_t, WF + XF>(b_real[r]);
    }
    for (int c = 0; c < cols; ++c) {
      x_real[c] = xd(rng());
      x[c] = hf::to_q<XF>(x_real[c]);
    }
    hf::matvec<WF, XF, YF>(w, x, bias, y);
    for (int r = 0; r < rows; ++r) {
      double expected = b_real[r];
      double bound = e_y + e_b + 1e-9;
      for (int c = 0; c < cols; ++c) {
        expected += w_real[r][c] * x_real[c];
        bound += std::fabs(x_real[c]) * e_w + std::fabs(w_real[r][c]) * e_x + e_w * e_x;
      }
      const double error = std::fabs(hf::to_real<YF, double>(y[r]) - expected);
      ASSERT_LE(error, bound) << "trial " << trial << " row " << r;
      worst_ratio = std::max(worst_ratio, error / bound);
    }
  }
  RecordProperty("worst_error_over_bound", std::to_string(worst_ratio));
}

}  // namespace
