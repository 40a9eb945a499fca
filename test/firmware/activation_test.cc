// Tests for firmware/core/activation.h: exhaustive over all 65536 int16
// inputs against double references written here (std::tanh, 1/(1+exp(-x))).
//
// Tolerances (stated once, the same numbers as the header's contract):
//  * tanh_q15:    |y/32768 - tanh(x/4096)|       <= 2^-13     (4 LSB)
//  * sigmoid_q15: |y/32768 - 1/(1+exp(-x/4096))| <= 5 * 2^-16 (2.5 LSB)
//  The double references are accurate to ~1e-16, far below 1 LSB = 2^-15, so
//  they need no slack. The measured maxima are printed and also pinned
//  (within 0.01 LSB) so that an accuracy change is noticed and documented.
#include "firmware/core/activation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

namespace hf = hadynet::fixed;

namespace {

constexpr int kMin = std::numeric_limits<std::int16_t>::min();
constexpr int kMax = std::numeric_limits<std::int16_t>::max();
constexpr double kLsb = 1.0 / 32768.0;  // output LSB, Q0.15

double input_real(int x) { return static_cast<double>(x) / 4096.0; }  // Q3.12
double output_real(std::int16_t y) { return static_cast<double>(y) * kLsb; }
double logistic(double v) { return 1.0 / (1.0 + std::exp(-v)); }

TEST(ActivationTable, MatchesFormula) {
  for (int i = 0; i < hf::detail::kTanhTableEntries; ++i) {
    const double scaled = 32768.0 * std::tanh(static_cast<double>(i) / 32.0);
    double expected = std::floor(scaled + 0.5);
    if (expected > 32767.0) {
      expected = 32767.0;
    }
    EXPECT_EQ(hf::detail::kTanhQ15Table[i], static_cast<std::int16_t>(expected)) << "i=" << i;
  }
}

TEST(ActivationTanh, ExhaustiveErrorWithinBound) {
  double max_err = 0.0;
  int worst = 0;
  for (int x = kMin; x <= kMax; ++x) {
    const double err = std::fabs(output_real(hf::tanh_q15(static_cast<std::int16_t>(x))) -
                                 std::tanh(input_real(x)));
    if (err > max_err) {
      max_err = err;
      worst = x;
    }
  }
  std::printf("tanh_q15 max |error| = %.4f LSB at x = %d\n", max_err / kLsb, worst);
  EXPECT_LE(max_err, std::ldexp(1.0, -13));
  EXPECT_NEAR(max_err / kLsb, 3.770, 0.01);  // value documented in activation.h
}

TEST(ActivationSigmoid, ExhaustiveErrorWithinBound) {
  double max_err = 0.0;
  int worst = 0;
  for (int x = kMin; x <= kMax; ++x) {
    const double err = std::fabs(output_real(hf::sigmoid_q15(static_cast<std::int16_t>(x))) -
                                 logistic(input_real(x)));
    if (err > max_err) {
      max_err = err;
      worst = x;
    }
  }
  std::printf("sigmoid_q15 max |error| = %.4f LSB at x = %d\n", max_err / kLsb, worst);
  EXPECT_LE(max_err, 5.0 * std::ldexp(1.0, -16));
  EXPECT_NEAR(max_err / kLsb, 2.385, 0.01);  // value documented in activation.h
}

TEST(ActivationTanh, ExactlyOddAndNeverMinusOne) {
  for (int x = kMin + 1; x <= kMax; ++x) {
    const int pos = hf::tanh_q15(static_cast<std::int16_t>(x));
    const int neg = hf::tanh_q15(static_cast<std::int16_t>(-x));
    ASSERT_EQ(neg, -pos) << "x=" << x;
    ASSERT_GE(pos, -32767) << "x=" << x;
  }
  // -32768 (-8.0) has no int16 negation; documented result is -tanh(32767).
  EXPECT_EQ(hf::tanh_q15(static_cast<std::int16_t>(kMin)), -32767);
  EXPECT_EQ(hf::tanh_q15(0), 0);
}

TEST(ActivationSigmoid, SymmetricWithinOneLsb) {
  for (int x = kMin + 1; x <= kMax; ++x) {
    const int sum = hf::sigmoid_q15(static_cast<std::int16_t>(x)) +
                    hf::sigmoid_q15(static_cast<std::int16_t>(-x));
    ASSERT_GE(sum, 32768) << "x=" << x;
    ASSERT_LE(sum, 32769) << "x=" << x;
  }
  EXPECT_EQ(hf::sigmoid_q15(0), 16384);
}

TEST(ActivationTanh, MonotoneNonDecreasing) {
  int prev = hf::tanh_q15(static_cast<std::int16_t>(kMin));
  for (int x = kMin + 1; x <= kMax; ++x) {
    const int y = hf::tanh_q15(static_cast<std::int16_t>(x));
    ASSERT_GE(y, prev) << "x=" << x;
    prev = y;
  }
}

TEST(ActivationSigmoid, MonotoneNonDecreasingAndInRange) {
  int prev = hf::sigmoid_q15(static_cast<std::int16_t>(kMin));
  for (int x = kMin; x <= kMax; ++x) {
    const int y = hf::sigmoid_q15(static_cast<std::int16_t>(x));
    ASSERT_GE(y, prev) << "x=" << x;
    ASSERT_GE(y, 11) << "x=" << x;
    ASSERT_LE(y, 32757) << "x=" << x;
    prev = y;
  }
}

TEST(ActivationSaturation, ExtremeInputsGiveRailValuesNoWrap) {
  const auto lo = static_cast<std::int16_t>(kMin);
  const auto hi = static_cast<std::int16_t>(kMax);
  EXPECT_EQ(hf::tanh_q15(hi), 32767);   // tanh(8 - 2^-12) rounds to +1.0: saturated
  EXPECT_EQ(hf::tanh_q15(lo), -32767);  // symmetric rail
  // sigmoid(8 - 2^-12) * 32768 = 32757.01, sigmoid(-8) * 32768 = 10.99.
  EXPECT_EQ(hf::sigmoid_q15(hi), 32757);
  EXPECT_EQ(hf::sigmoid_q15(lo), 11);
  // The top of the input range stays at the rail (no wrap to negative).
  for (int x = 30000; x <= kMax; ++x) {
    ASSERT_GT(hf::tanh_q15(static_cast<std::int16_t>(x)), 32700) << "x=" << x;
    ASSERT_GT(hf::sigmoid_q15(static_cast<std::int16_t>(x)), 32700) << "x=" << x;
  }
  for (int x = kMin; x <= -30000; ++x) {
    ASSERT_LT(hf::tanh_q15(static_cast<std::int16_t>(x)), -32700) << "x=" << x;
    ASSERT_LT(hf::sigmoid_q15(static_cast<std::int16_t>(x)), 100) << "x=" << x;
  }
}

}  // namespace
