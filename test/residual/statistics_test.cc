// Statistics of the residual loop against known answers. Tolerances: the
// distribution tails are compared with textbook quantiles printed to 12-16
// significant digits (or closed forms), so 1e-9 relative; the random-series
// tests use fixed seeds and state their bounds where they appear.
#include "trainer/residual/statistics.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

namespace hadynet::trainer::residual {
namespace {

Eigen::VectorXd white_noise(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = normal(rng);
  return v;
}

Eigen::VectorXd ar1(int n, double phi, std::uint64_t seed) {
  Eigen::VectorXd e = white_noise(n, seed), v(n);
  v(0) = e(0);
  for (int i = 1; i < n; ++i) v(i) = phi * v(i - 1) + e(i);
  return v;
}

TEST(Distributions, ChiSquareTailsMatchTextbookQuantiles) {
  EXPECT_NEAR(chi_square_sf(3.841458820694124, 1), 0.05, 1e-9 * 0.05);
  EXPECT_NEAR(chi_square_sf(6.634896601021214, 1), 0.01, 1e-9 * 0.01);
  EXPECT_NEAR(chi_square_sf(23.20925115895436, 10), 0.01, 1e-9 * 0.01);
  EXPECT_NEAR(chi_square_sf(37.65248413348278, 25), 0.05, 1e-9 * 0.05);
  EXPECT_NEAR(chi_square_sf(44.31410489621915, 25), 0.01, 1e-9 * 0.01);
  // Two degrees of freedom: P(X > q) = exp(-q / 2), also far in the tail
  // (the continued fraction's side).
  for (double q : {0.1, 1.0, 5.0, 40.0, 300.0}) EXPECT_NEAR(chi_square_sf(q, 2) / std::exp(-q / 2), 1.0, 1e-12);
  EXPECT_EQ(chi_square_sf(0.0, 5), 1.0);
}

TEST(Distributions, IncompleteGammaAndBetaClosedForms) {
  for (double x : {0.01, 0.5, 1.0, 3.0, 20.0}) {
    EXPECT_NEAR(gamma_p(1.0, x), 1.0 - std::exp(-x), 1e-14);           // exponential
    EXPECT_NEAR(gamma_p(0.5, x), std::erf(std::sqrt(x)), 1e-13);        // half-integer
    EXPECT_NEAR(gamma_p(3.0, x) + gamma_q(3.0, x), 1.0, 1e-14);
  }
  for (double x : {0.0, 0.2, 0.7, 1.0}) EXPECT_NEAR(beta_inc(2.5, 1.0, x), std::pow(x, 2.5), 1e-13);
  EXPECT_NEAR(beta_inc(2.0, 3.0, 0.4), 0.5248, 1e-13);  // 1 - sum_{k<2} C(4,k) 0.4^k 0.6^(4-k)
  EXPECT_THROW(gamma_p(-1.0, 1.0), std::domain_error);
  EXPECT_THROW(beta_inc(1.0, 1.0, 1.5), std::domain_error);
}

TEST(Distributions, StudentTAndF) {
  EXPECT_NEAR(student_t_sf(2.228138851986274, 10), 0.025, 1e-9 * 0.025);
  EXPECT_NEAR(student_t_sf(2.575829303548901, 1e9), 0.005, 1e-7);  // -> normal
  for (double t : {-3.0, 0.5, 4.0}) EXPECT_NEAR(student_t_sf(t, 1), 0.5 - std::atan(t) / std::numbers::pi, 1e-13);
  EXPECT_NEAR(f_sf(4.964602743730711, 1, 10), 0.05, 1e-9 * 0.05);
  EXPECT_NEAR(f_sf(3.0 * 3.0, 1, 25), 2 * student_t_sf(3.0, 25), 1e-13);  // F(1, n) = t^2
}

TEST(Whiteness, WhiteNoisePassesAcrossPooledLogs) {
  // Three logs with different offsets: pooling centres each log on its own mean.
  const Segments logs = {white_noise(700, 1).array() + 5.0, white_noise(700, 2).array() - 3.0, white_noise(700, 3)};
  const LjungBox lb = ljung_box(logs, 25);
  EXPECT_EQ(lb.dof, 25);
  // Under H0 the p-value is uniform; with these fixed seeds it is well inside.
  EXPECT_GT(lb.p_value, 0.01);
  const Eigen::VectorXd acf = autocorrelation(logs, 25);
  const double bound = correlation_bound_99(total_samples(logs));
  EXPECT_NEAR(bound, 2.58 / std::sqrt(2100.0), 1e-15);
  EXPECT_LE((acf.array().abs() > bound).count(), 2);  // expected 0.25 of 25 lags
}

TEST(Whiteness, Ar1FailsAndItsAutocorrelationIsPhi) {
  const Segments logs = {ar1(1000, 0.5, 7), ar1(1000, 0.5, 8)};
  const LjungBox lb = ljung_box(logs, 25);
  EXPECT_LT(lb.p_value, 1e-30);
  const Eigen::VectorXd acf = autocorrelation(logs, 3);
  // rho_k = 0.5^k; the sampling sd is about 1/sqrt(2000) = 0.022, so 0.07 is 3 sd.
  EXPECT_NEAR(acf(0), 0.5, 0.07);
  EXPECT_NEAR(acf(1), 0.25, 0.07);
  EXPECT_NEAR(fit_ar(logs, 1)(0), 0.5, 0.07);
  EXPECT_EQ(choose_ar_order(logs, 10), 1);
  // The whitened series is white.
  EXPECT_GT(ljung_box(ar_filter(logs, fit_ar(logs, 1)), 25).p_value, 0.01);
}

// choose_ar_order's BIC with every order fitted on its own (one
// column-pivoting QR per order on the rows t >= max_order of each centred
// segment): what choose_ar_order computed before its one factorisation.
int ar_order_fitted_per_order(const Segments& x, int max_order) {
  std::vector<double> y;
  std::vector<std::vector<double>> lags;
  for (const Eigen::VectorXd& raw : x) {
    const Eigen::VectorXd s = raw.array() - raw.mean();
    for (Eigen::Index t = max_order; t < s.size(); ++t) {
      y.push_back(s(t));
      std::vector<double> row;
      for (int i = 1; i <= max_order; ++i) row.push_back(s(t - i));
      lags.push_back(row);
    }
  }
  const auto n = static_cast<Eigen::Index>(y.size());
  const Eigen::VectorXd Y = Eigen::Map<const Eigen::VectorXd>(y.data(), n);
  int best = 0;
  double best_bic = std::numeric_limits<double>::infinity();
  for (int p = 0; p <= max_order; ++p) {
    Eigen::MatrixXd X(n, p);
    for (Eigen::Index r = 0; r < n; ++r)
      for (int i = 0; i < p; ++i) X(r, i) = lags[static_cast<std::size_t>(r)][static_cast<std::size_t>(i)];
    const double rss = p == 0 ? Y.squaredNorm() : (Y - X * X.colPivHouseholderQr().solve(Y)).squaredNorm();
    const double bic = static_cast<double>(n) * std::log(std::max(rss / static_cast<double>(n), 1e-300)) +
                       p * std::log(static_cast<double>(n));
    if (bic < best_bic) best_bic = bic, best = p;
  }
  return best;
}

// An AR(2) with coefficients phi1, phi2 (stationary for the values used).
Eigen::VectorXd ar2(int n, double phi1, double phi2, std::uint64_t seed) {
  Eigen::VectorXd e = white_noise(n, seed), v(n);
  for (int i = 0; i < n; ++i) v(i) = e(i) + (i >= 1 ? phi1 * v(i - 1) : 0) + (i >= 2 ? phi2 * v(i - 2) : 0);
  return v;
}

// The order from one factorisation is the order every order fitted on its
// own gives: exactly (an integer), on series of orders 0, 1 and 2, short
// and long, and on a periodic series whose lags are collinear (lag 2 = -lag
// 1: the per-order fits take it).
TEST(Whiteness, TheArOrderIsTheOneEveryOrderFittedOnItsOwnGives) {
  std::vector<Segments> cases;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    cases.push_back({white_noise(300, seed)});
    cases.push_back({ar1(120, 0.7, seed), ar1(80, 0.7, seed + 100)});
    cases.push_back({ar2(400, 0.5, -0.3, seed), ar2(250, 0.5, -0.3, seed + 200)});
    cases.push_back({ar2(60, 1.2, -0.5, seed)});
  }
  Eigen::VectorXd alternating(40);
  for (int i = 0; i < 40; ++i) alternating(i) = i % 2 ? -1.0 : 1.0;
  cases.push_back({alternating});
  std::vector<int> seen(11, 0);
  for (const Segments& x : cases) {
    const int order = choose_ar_order(x, 10);
    EXPECT_EQ(order, ar_order_fitted_per_order(x, 10));
    ++seen[static_cast<std::size_t>(order)];
  }
  EXPECT_EQ(choose_ar_order({alternating}, 10), 1);  // x_t = -x_{t-1} exactly
  // The cases reach orders 0, 1 and 2 (the comparison is not of one order).
  EXPECT_GT(seen[0], 0);
  EXPECT_GT(seen[1], 0);
  EXPECT_GT(seen[2], 0);
}

TEST(Whiteness, NoProductAcrossLogBoundaries) {
  // Each log alternates +1/-1 inside; concatenated naively, the boundary would add a +1 product.
  Eigen::VectorXd a(4), b(4);
  a << 1, -1, 1, -1;
  b << 1, -1, 1, -1;
  const Eigen::VectorXd acf = autocorrelation({a, b}, 1);
  EXPECT_DOUBLE_EQ(acf(0), -6.0 / 8.0);  // 3 pairs per log, each -1; sum of squares 8
  EXPECT_EQ(pairs_at_lag({a, b}, 1), 6);
}

TEST(CrossCorrelation, DelayedCopyPeaksAtTheDelay) {
  const Eigen::VectorXd u = white_noise(1500, 11), e = white_noise(1500, 12);
  Eigen::VectorXd r = 0.3 * e;
  for (int t = 3; t < 1500; ++t) r(t) += u(t - 3);  // r_t = u_{t-3} + noise
  const Eigen::VectorXd rho = cross_correlation({r}, {u}, 25);
  Eigen::Index at = 0;
  rho.cwiseAbs().maxCoeff(&at);
  EXPECT_EQ(at - 25, 3);  // positive lag: the input leads
  EXPECT_GT(rho(at), 0.9);
  const double bound = correlation_bound_99(1500);
  for (Eigen::Index k = 0; k < rho.size(); ++k)
    if (k != at) {
      EXPECT_LT(std::abs(rho(k)), 2 * bound) << "lag " << k - 25;
    }
}

TEST(MultipleComparisons, HolmMatchesHandComputation) {
  const std::vector<double> adjusted = holm_adjust({0.01, 0.04, 0.03, 0.005});
  // sorted: 0.005*4 = 0.02, 0.01*3 = 0.03, 0.03*2 = 0.06, 0.04*1 -> max(0.06, 0.04)
  EXPECT_DOUBLE_EQ(adjusted[3], 0.02);
  EXPECT_DOUBLE_EQ(adjusted[0], 0.03);
  EXPECT_DOUBLE_EQ(adjusted[2], 0.06);
  EXPECT_DOUBLE_EQ(adjusted[1], 0.06);
  EXPECT_DOUBLE_EQ(holm_adjust({0.9, 0.8})[0], 1.0);
}

// Diebold-Mariano under the null, with strongly autocorrelated loss
// differences (AR(1), phi 0.8, as a model's per-row losses are): with the
// Newey-West variance the one-sided test rejects at 1 % in about 1 % of 400
// independent trials. Tolerance: at most 4 % (binomial 400 x 1 %: P(> 16) <
// 0.001; an i.i.d. variance here rejects in about 8 % - the test below
// shows the difference).
TEST(DieboldMariano, AutocorrelatedNullKeepsItsLevel) {
  int rejected_hac = 0, rejected_iid = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Segments a = {ar1(600, 0.8, 1000 + trial), ar1(400, 0.8, 5000 + trial)};
    const Segments b = {Eigen::VectorXd::Zero(600), Eigen::VectorXd::Zero(400)};
    rejected_hac += diebold_mariano(a, b).p_value < 0.01;
    rejected_iid += diebold_mariano(a, b, 0).p_value < 0.01;
  }
  std::printf("null rejections at 1 %%: Newey-West %d / 400, i.i.d. variance %d / 400\n", rejected_hac, rejected_iid);
  EXPECT_LE(rejected_hac, 16);
  EXPECT_GT(rejected_iid, rejected_hac);
}

// A real improvement of B (loss lower by 0.3 on average, AR(1) noise) is
// found; swapped, it is not. Pairs never span two segments: one segment's
// constant offset cannot leak into another's lags.
TEST(DieboldMariano, FindsTheBetterModelOneSided) {
  const Segments a = {ar1(800, 0.5, 7), ar1(800, 0.5, 8)};
  const Segments b = {a[0].array() - 0.3 + 0.5 * ar1(800, 0.5, 9).array(),
                      a[1].array() - 0.3 + 0.5 * ar1(800, 0.5, 10).array()};
  const DieboldMariano better = diebold_mariano(a, b);
  // The mean difference within the noise of 1600 AR(1) samples (sd ~ 0.025).
  EXPECT_NEAR(better.mean, 0.3, 0.1);
  EXPECT_LT(better.p_value, 1e-6);
  EXPECT_GT(diebold_mariano(b, a).p_value, 0.99);
  EXPECT_EQ(better.samples, 1600);
  EXPECT_GT(better.bandwidth, 0);
  EXPECT_LE(better.bandwidth, 400);
  EXPECT_THROW(diebold_mariano(a, {a[0]}), std::invalid_argument);
}

// Two models' squared errors on four logs of different size (scales 1, 0.5,
// 0.3 and 3: a hard grasp's errors are ten times an easy one's), sharing
// most of their error (AR(1), phi 0.8, 120 rows per log, as a fold's
// held-out rows). `gain` scales the shared error of B on the first three
// logs; the fourth, largest, has none.
std::pair<Segments, Segments> two_models_on_four_logs(double gain, std::uint64_t seed) {
  const double scales[] = {1, 0.5, 0.3, 3};
  Segments a, b;
  for (int k = 0; k < 4; ++k) {
    const std::uint64_t s = seed * 16 + static_cast<std::uint64_t>(k) * 4;
    const Eigen::VectorXd shared = ar1(120, 0.8, s);
    const double g = k < 3 ? gain : 1.0;
    a.push_back((scales[k] * (shared + 0.5 * ar1(120, 0.8, s + 1))).array().square().matrix());
    b.push_back((scales[k] * (g * shared + 0.5 * ar1(120, 0.8, s + 2))).array().square().matrix());
  }
  return {a, b};
}

int rejections_at_1_percent(double gain, int trials, std::uint64_t first_seed, bool relative) {
  int rejected = 0;
  for (int trial = 0; trial < trials; ++trial) {
    auto [a, b] = two_models_on_four_logs(gain, first_seed + static_cast<std::uint64_t>(trial));
    if (relative) relative_to_segment_level(a, b);
    rejected += diebold_mariano(a, b).p_value < 0.01;
  }
  return rejected;
}

// Equal accuracy on every log: with each log in its own level the test
// still rejects at 1 % in about 1 % of 400 trials (5 of 400 here).
// Tolerance: at most 16 (binomial 400 x 1 %: P(> 16) < 0.001), as the
// plain test's above.
TEST(DieboldMariano, EachLogInItsOwnLevelKeepsTheNullsLevel) {
  const int rejected = rejections_at_1_percent(1.0, 400, 20000, true);
  std::printf("null rejections at 1 %% with each log in its own level: %d / 400\n", rejected);
  EXPECT_LE(rejected, 16);
}

// B's shared error is 0.7 of A's on three logs and the same on the largest:
// with each log in its own level the test finds B better in most of 100
// trials (72 here), the rows as they come almost never (5 here: the
// largest log's noise carries the test). Tolerances: at least 50 and at
// most 15 (binomial 100 x 0.72: P(< 50) < 1e-5; 100 x 0.05: P(> 15) <
// 1e-3).
TEST(DieboldMariano, EachLogInItsOwnLevelFindsAGainTheLargestLogHides) {
  const int relative = rejections_at_1_percent(0.7, 100, 30000, true);
  const int as_they_come = rejections_at_1_percent(0.7, 100, 30000, false);
  std::printf("gain found at 1 %%: each log in its own level %d / 100, the rows as they come %d / 100\n", relative,
              as_they_come);
  EXPECT_GE(relative, 50);
  EXPECT_LE(as_they_come, 15);
}

// Each segment is divided by the pair's mean there; a segment of level 0
// stays; segments that do not pair are refused.
TEST(DieboldMariano, EachLogInItsOwnLevelDividesBySegmentPairsMean) {
  Segments a = {Eigen::Vector2d(2, 4), Eigen::Vector2d(0, 0)};
  Segments b = {Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 0)};
  relative_to_segment_level(a, b);  // level of the first pair: (3 + 1) / 2 = 2
  EXPECT_DOUBLE_EQ(a[0](0), 1.0);
  EXPECT_DOUBLE_EQ(a[0](1), 2.0);
  EXPECT_DOUBLE_EQ(b[0](0), 0.5);
  EXPECT_DOUBLE_EQ(a[1](0), 0.0);
  Segments one = {Eigen::Vector2d(1, 1)};
  Segments other_size = {Eigen::Vector3d(1, 1, 1)};
  EXPECT_THROW(relative_to_segment_level(one, other_size), std::invalid_argument);
  EXPECT_THROW(relative_to_segment_level(one, a), std::invalid_argument);
}

}  // namespace
}  // namespace hadynet::trainer::residual
