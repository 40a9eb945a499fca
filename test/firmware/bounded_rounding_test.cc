// The hot loops' rounding (bounded_rounding.h) against fixed_point.h's
// reference, on the domains bounded_rounding.h states: equal bit for bit at
// the domains' edges, at the ties around random values of every magnitude,
// on those values, and on every int16 input where that is cheap. No
// tolerance: the contract is equality.
#include "firmware/core/bounded_rounding.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "firmware/core/fixed_point.h"

namespace hadynet::fixed {
namespace {

constexpr std::int64_t k2p62 = std::int64_t{1} << 62;

// Values of every magnitude up to 2^bits (both signs), the edges, and the
// ties of `shift` around them.
std::vector<std::int64_t> samples(int bits, int shift) {
  std::vector<std::int64_t> v = {0, 1, -1, 2, -2};
  std::mt19937_64 rng(static_cast<std::uint64_t>(bits * 64 + shift));
  for (int b = 1; b <= bits; ++b) {
    const std::int64_t top = b == 63 ? INT64_MAX : (std::int64_t{1} << b) - 1;
    v.push_back(top);
    v.push_back(-top);
    v.push_back(-top - 1);
    for (int k = 0; k < 40; ++k) {
      const auto r = static_cast<std::int64_t>(rng() & static_cast<std::uint64_t>(top));
      v.push_back(r);
      v.push_back(-r);
      // The ties around r: r rounded down to a multiple of 2^shift, plus half.
      const std::int64_t tie = (r >> shift << shift) + (std::int64_t{1} << (shift - 1));
      for (const std::int64_t d : {-1, 0, 1}) {
        if (d <= 0 || tie < top) {
          v.push_back(tie + d);
          v.push_back(-(tie + d));
        }
      }
    }
  }
  return v;
}

template <int Shift>
void check_shift_i64() {
  for (const std::int64_t x : samples(62, Shift)) {
    if (x > k2p62 || x < -k2p62) continue;
    ASSERT_EQ(bounded::rounding_shift_right<Shift>(x), rounding_shift_right(x, Shift)) << "x=" << x;
    ASSERT_EQ((bounded::requantize_i32<Shift + 3, 3>(x)), (requantize_i32<Shift + 3, 3>(x))) << "x=" << x;
    ASSERT_EQ((bounded::requantize_i16<Shift + 3, 3>(x)), (requantize_i16<Shift + 3, 3>(x))) << "x=" << x;
  }
  for (const std::int64_t x : {k2p62, -k2p62, k2p62 - 1, -k2p62 + 1}) {
    ASSERT_EQ(bounded::rounding_shift_right<Shift>(x), rounding_shift_right(x, Shift)) << "x=" << x;
  }
}

TEST(BoundedRounding, Int64ShiftsEqualTheReferenceUpTo2p62) {
  check_shift_i64<1>();
  check_shift_i64<2>();
  check_shift_i64<11>();
  check_shift_i64<15>();
  check_shift_i64<19>();
  check_shift_i64<30>();
  check_shift_i64<31>();
  check_shift_i64<40>();
  check_shift_i64<59>();
}

template <int Shift>
void check_shift_i32() {
  constexpr std::int64_t max = INT32_MAX - (std::int64_t{1} << (Shift - 1));
  for (const std::int64_t x : samples(31, Shift)) {
    if (x > max || x < INT32_MIN) continue;
    const auto x32 = static_cast<std::int32_t>(x);
    ASSERT_EQ(bounded::rounding_shift_right_i32<Shift>(x32), rounding_shift_right(x, Shift)) << "x=" << x;
  }
  ASSERT_EQ(bounded::rounding_shift_right_i32<Shift>(static_cast<std::int32_t>(max)), rounding_shift_right(max, Shift));
  ASSERT_EQ(bounded::rounding_shift_right_i32<Shift>(INT32_MIN), rounding_shift_right(INT32_MIN, Shift));
}

TEST(BoundedRounding, Int32ShiftsEqualTheReferenceOnTheirDomain) {
  check_shift_i32<1>();
  check_shift_i32<4>();
  check_shift_i32<15>();
  check_shift_i32<19>();
  check_shift_i32<30>();
}

TEST(BoundedRounding, SaturationEqualsTheReference) {
  for (const std::int64_t x : samples(63, 1)) {
    ASSERT_EQ(bounded::saturate_i32(x), saturate_i32(x)) << "x=" << x;
    if (x >= INT32_MIN && x <= INT32_MAX) {
      ASSERT_EQ(bounded::saturate_i16(static_cast<std::int32_t>(x)), saturate_i16(x)) << "x=" << x;
    }
  }
  ASSERT_EQ(bounded::saturate_i32(INT64_MIN), INT32_MIN);
  ASSERT_EQ(bounded::saturate_i32(INT64_MAX), INT32_MAX);
}

// Every int16 input and, for mul, every pair on a grid plus all edges.
TEST(BoundedRounding, Int16RescaleAndMulEqualTheReference) {
  for (std::int32_t v = INT16_MIN; v <= INT16_MAX; ++v) {
    const auto x = static_cast<std::int16_t>(v);
    ASSERT_EQ((bounded::rescale_i16<11, 12>(x)), (requantize_i16<11, 12>(x))) << v;
    ASSERT_EQ((bounded::rescale_i16<11, 4>(x)), (requantize_i16<11, 4>(x))) << v;
    ASSERT_EQ((bounded::rescale_i16<0, 15>(x)), (requantize_i16<0, 15>(x))) << v;
    ASSERT_EQ((bounded::rescale_i16<15, 0>(x)), (requantize_i16<15, 0>(x))) << v;
  }
  std::vector<std::int16_t> grid = {INT16_MIN, INT16_MIN + 1, -1, 0, 1, INT16_MAX - 1, INT16_MAX};
  for (std::int32_t v = INT16_MIN; v <= INT16_MAX; v += 97) grid.push_back(static_cast<std::int16_t>(v));
  for (const std::int16_t a : grid) {
    for (const std::int16_t b : grid) {
      ASSERT_EQ((bounded::mul<15, 15, 11>(a, b)), (mul<15, 15, 11>(a, b))) << a << " " << b;
      ASSERT_EQ((bounded::mul<15, 15, 0>(a, b)), (mul<15, 15, 0>(a, b))) << a << " " << b;
      ASSERT_EQ((bounded::mul<12, 9, 14>(a, b)), (mul<12, 9, 14>(a, b))) << a << " " << b;
    }
  }
}

// The cell update against its definition (requantize_i16 of the exact
// int64 sum), for C = 11 (the hand's model), 0, 14 and 15: the edges of
// every input, then random inputs, then random ties (i g with zero low bits).
template <int C>
void check_cell_update() {
  const auto reference = [](std::int16_t f, std::int16_t c, std::int16_t i, std::int16_t g) {
    return requantize_i16<30 + C, C>(std::int64_t{f} * c * 32768 + std::int64_t{i} * g * (std::int64_t{1} << C));
  };
  const std::vector<std::int16_t> edges = {INT16_MIN, INT16_MIN + 1, -16384, -1, 0, 1, 16384, INT16_MAX - 1, INT16_MAX};
  for (const auto f : edges)
    for (const auto c : edges)
      for (const auto i : edges)
        for (const auto g : edges) ASSERT_EQ(bounded::cell_update<C>(f, c, i, g), reference(f, c, i, g));
  std::mt19937 rng(C);
  std::uniform_int_distribution<int> any(INT16_MIN, INT16_MAX);
  const auto draw = [&] { return static_cast<std::int16_t>(any(rng)); };
  for (int n = 0; n < 400000; ++n) {
    const std::int16_t f = draw(), c = draw(), i = draw(), g = draw();
    ASSERT_EQ(bounded::cell_update<C>(f, c, i, g), reference(f, c, i, g)) << f << " " << c << " " << i << " " << g;
    // i g's low bits zero (g a multiple of 2^(15 - C)) ...
    const auto g_low = static_cast<std::int16_t>(g & ~((1 << (15 - C)) - 1));
    ASSERT_EQ(bounded::cell_update<C>(f, c, i, g_low), reference(f, c, i, g_low)) << f << " " << c << " " << i << " " << g_low;
    // ... and a real tie: with f = +-1 the sum is 2^C (2^k a + 0), a tie
    // when a = +-c + (i g >> k) is 2^14 mod 2^15; c picked to make it so.
    if constexpr (C < 15) {
      constexpr int k = 15 - C;
      const std::int32_t high = (std::int32_t{i} * g_low) >> k;
      const std::int32_t need = ((std::int32_t{1} << 14) - high) & 0x7FFF;  // c mod 2^15
      for (const std::int32_t c_tie : {need, need - 32768}) {
        const auto ct = static_cast<std::int16_t>(c_tie);
        ASSERT_EQ(bounded::cell_update<C>(1, ct, i, g_low), reference(1, ct, i, g_low)) << ct << " " << i << " " << g_low;
        const auto cn = static_cast<std::int16_t>(-c_tie == 32768 ? -32768 : -c_tie);
        ASSERT_EQ(bounded::cell_update<C>(-1, cn, i, g_low), reference(-1, cn, i, g_low)) << cn << " " << i << " " << g_low;
      }
    }
  }
}

// The gate slopes' roundings (numerics.h: s (2^15 - s) and t^2, both >> 15
// in int32) on every int16 input.
TEST(BoundedRounding, SlopeRoundingsEqualTheReferenceOnEveryInput) {
  for (std::int32_t v = INT16_MIN; v <= INT16_MAX; ++v) {
    const std::int32_t sigmoid_product = v * (32768 - v);
    ASSERT_EQ(bounded::rounding_shift_right_i32<15>(sigmoid_product), rounding_shift_right(sigmoid_product, 15)) << v;
    const std::int32_t tanh_product = v * v;
    ASSERT_EQ(bounded::rounding_shift_right_i32<15>(tanh_product), rounding_shift_right(tanh_product, 15)) << v;
  }
}

TEST(BoundedRounding, CellUpdateEqualsItsInt64Definition) {
  check_cell_update<11>();
  check_cell_update<0>();
  check_cell_update<14>();
  check_cell_update<15>();
}

}  // namespace
}  // namespace hadynet::fixed
