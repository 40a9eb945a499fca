// Block floating point gradients (numerics.h, grad_block_q15): the form the
// packed W^T kernel reads. The contract: the smallest exponent s >= 0 that
// fits the largest |g| in 15 bits, mantissas rounded as
// fixed::rounding_shift_right (half away from zero) and saturated, exact
// while every |g| < 2^15.
#include "firmware/core/numerics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "firmware/core/fixed_point.h"

namespace hadynet::firmware {
namespace {

// The contract, written from its definition.
int expected_shift(const std::vector<std::int32_t>& g) {
  std::int64_t max_abs = 0;
  for (const std::int32_t v : g) max_abs = std::max(max_abs, v < 0 ? -std::int64_t{v} : std::int64_t{v});
  int s = 0;
  while ((max_abs >> s) >= (std::int64_t{1} << 15)) ++s;
  return s;
}

void check(const std::vector<std::int32_t>& g) {
  std::vector<std::int16_t> m(g.size());
  const int s = grad_block_q15(g.data(), static_cast<int>(g.size()), m.data());
  ASSERT_EQ(s, expected_shift(g));
  for (std::size_t i = 0; i < g.size(); ++i) {
    ASSERT_EQ(m[i], fixed::saturate_i16(fixed::rounding_shift_right(g[i], s))) << "g=" << g[i] << " s=" << s;
    // Within half an LSB of g / 2^s, except where the largest rounds up to
    // 2^15 and saturates (one LSB then).
    const std::int64_t error = std::int64_t{m[i]} * (std::int64_t{1} << s) - g[i];
    ASSERT_LE(error < 0 ? -error : error, std::int64_t{1} << s) << "g=" << g[i];
  }
}

TEST(GradBlockQ15, SmallGradientsAreExact) {
  const std::vector<std::int32_t> g = {0, 1, -1, 32767, -32767, -32768 + 1, 12345, -20000};
  std::vector<std::int16_t> m(g.size());
  EXPECT_EQ(grad_block_q15(g.data(), static_cast<int>(g.size()), m.data()), 0);
  for (std::size_t i = 0; i < g.size(); ++i) EXPECT_EQ(m[i], g[i]);
}

TEST(GradBlockQ15, ExponentFollowsTheLargestMagnitude) {
  check({32768});                   // 16 bits: s = 1, mantissa 16384
  check({-32768, 5});               // |-32768| has 16 bits
  check({65535, -3});               // 65535 / 2 = 32767.5 rounds to 32768: saturates
  check({1 << 20, -(1 << 20) + 1, 7});
  check({INT32_MIN, INT32_MAX, 0, -1, 1});  // s = 17
  check({0, 0, 0});
  // Where the int32 rounding (s <= 15) meets the int64 one (s = 16, 17).
  check({(1 << 30) - 1, -5, 16385, -16385});        // s = 15
  check({-(1 << 30) + 1, 5, (1 << 30) - (1 << 14)});  // s = 15, the largest |g| + half
  check({1 << 30, -3, 32769});                       // s = 16
  check({-(1 << 30), 3, -32769});                    // s = 16
}

TEST(GradBlockQ15, TiesRoundAwayFromZero) {
  std::vector<std::int32_t> g = {1 << 16, 3, -3, 5, -5};  // s = 2: 3/4, 5/4 ...
  check(g);
  std::vector<std::int16_t> m(g.size());
  ASSERT_EQ(grad_block_q15(g.data(), static_cast<int>(g.size()), m.data()), 2);
  EXPECT_EQ(m[1], 1);   // 0.75
  EXPECT_EQ(m[2], -1);  // -0.75
  g = {1 << 16, 2, -2, 6, -6};  // 0.5, -0.5, 1.5, -1.5
  ASSERT_EQ(grad_block_q15(g.data(), static_cast<int>(g.size()), m.data()), 2);
  EXPECT_EQ(m[1], 1);
  EXPECT_EQ(m[2], -1);
  EXPECT_EQ(m[3], 2);
  EXPECT_EQ(m[4], -2);
}

TEST(GradBlockQ15, RandomVectorsOfEveryScale) {
  std::mt19937 rng(7);
  for (int bits = 1; bits <= 32; ++bits) {
    std::uniform_int_distribution<std::int64_t> dist(-(std::int64_t{1} << (bits - 1)), (std::int64_t{1} << (bits - 1)) - 1);
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<std::int32_t> g(1 + trial * 25);
      for (auto& v : g) v = static_cast<std::int32_t>(dist(rng));
      check(g);
    }
  }
}

}  // namespace
}  // namespace hadynet::firmware
