// Central finite differences and the one gradient tolerance of the trainer
// tests.
//
// Step h = 1e-6 in double: the truncation error of a central difference is
// h^2/6 |f'''| ~ 2e-13 for the O(1) derivatives of these small networks, the
// rounding error is ~ eps |L| / h ~ 1e-10 for losses L ~ O(1). Hence an
// analytic gradient g passes against the difference d when
//   |g - d| <= 1e-6 * max(|g|, |d|) + 1e-8,
// i.e. 1e-6 relative for every gradient above ~1e-2 and an absolute floor
// (two orders above the rounding error) for the small and the exactly-zero
// ones (enc.bias in BN training mode is analytically zero: the batch mean
// removes it).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace hadynet::trainer::testing {

inline constexpr double kFdStep = 1e-6;
inline constexpr double kGradRelTol = 1e-6;
inline constexpr double kGradAbsTol = 1e-8;

// (f(v + h) - f(v - h)) / 2h, with *value restored afterwards.
template <class F>
double central_difference(double* value, F&& f) {
  const double saved = *value;
  *value = saved + kFdStep;
  const double plus = f();
  *value = saved - kFdStep;
  const double minus = f();
  *value = saved;
  return (plus - minus) / (2.0 * kFdStep);
}

inline ::testing::AssertionResult gradient_close(double analytic, double numeric) {
  const double bound = kGradRelTol * std::max(std::abs(analytic), std::abs(numeric)) + kGradAbsTol;
  if (std::abs(analytic - numeric) <= bound) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "analytic " << analytic << " vs finite difference " << numeric << " (|diff| "
         << std::abs(analytic - numeric) << " > " << bound << ")";
}

}  // namespace hadynet::trainer::testing
