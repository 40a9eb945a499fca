// Per-channel standardisation (trainer/normalization.h): exact moments on
// hand-made data, the std floor relative to the group median, std 1 for a
// constant group, pooling over sequences.
#include "trainer/normalization.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "synthetic_logs.h"

namespace hadynet::trainer::testing {
namespace {

// Moments are sums of a few small values: a correct implementation is within
// a few ulps; 1e-12 relative fails for any wrong formula (e.g. n-1 instead of
// n changes a std by >= 10 %).
constexpr double kRel = 1e-12;

void expect_near_rel(double got, double want, const char* what) {
  EXPECT_NEAR(got, want, kRel * std::max(1.0, std::abs(want))) << what;
}

// Population mean and std of values, two-pass.
std::pair<double, double> moments(const std::vector<double>& v) {
  double mean = 0.0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double var = 0.0;
  for (double x : v) var += (x - mean) * (x - mean);
  return {mean, std::sqrt(var / static_cast<double>(v.size()))};
}

// y = (q0, q1, v0, v1, v2), u = (u0), delta group q; T = 4.
//   q0 = 1, 3, 5, 7       dq0 = 2, 2, 2        (constant difference)
//   q1 = 0,-1,-2,-3       dq1 = -1,-1,-1       (so the group dq is constant)
//   v0 = 0,40, 0,40       std 20
//   v1 = 0,200,0,200      std 100
//   v2 = 1, 1, 1, 1.001   std 4.3e-4, below 0.1 x median(v stds) = 2
//   u0 = 1,-1, 1,-1
struct Known {
  FeatureLayout layout = feature_layout_from_names({"q0", "q1", "v0", "v1", "v2"}, {"u0"}, {"q"});
  LogSequence seq;
  Known() {
    seq.file = "known.csv";
    seq.y.resize(5, 4);
    seq.y << 1, 3, 5, 7,  //
        0, -1, -2, -3,    //
        0, 40, 0, 40,     //
        0, 200, 0, 200,   //
        1, 1, 1, 1.001;
    seq.u.resize(1, 4);
    seq.u << 1, -1, 1, -1;
  }
  std::vector<double> row(int r, int from = 0) const {
    std::vector<double> v;
    for (int t = from; t < 4; ++t) v.push_back(seq.y(r, t));
    return v;
  }
};

TEST(Normalization, MeanAndPopulationStdOfYAndU) {
  const Known k;
  const Normalization n = fit_normalization({k.seq}, k.layout);
  ASSERT_EQ(n.y.mean.size(), 5);
  expect_near_rel(n.y.mean(0), 4.0, "q0 mean");
  expect_near_rel(n.y.std(0), std::sqrt(5.0), "q0 std (population)");
  expect_near_rel(n.y.mean(1), -1.5, "q1 mean");
  expect_near_rel(n.y.std(1), std::sqrt(1.25), "q1 std");
  expect_near_rel(n.y.mean(2), 20.0, "v0 mean");
  expect_near_rel(n.y.std(2), 20.0, "v0 std");
  expect_near_rel(n.y.std(3), 100.0, "v1 std");
  expect_near_rel(n.u.mean(0), 0.0, "u0 mean");
  expect_near_rel(n.u.std(0), 1.0, "u0 std");
}

TEST(Normalization, XUsesStepsFromOneOnAndTheDifferences) {
  const Known k;
  const Normalization n = fit_normalization({k.seq}, k.layout);
  // x = q0 q1 dq0 dq1 v0 v1 v2, over t = 1..3
  ASSERT_EQ(n.x.mean.size(), 7);
  const auto [q0_mean, q0_std] = moments(k.row(0, 1));
  expect_near_rel(n.x.mean(0), q0_mean, "x q0 mean");
  expect_near_rel(n.x.std(0), q0_std, "x q0 std");
  EXPECT_NE(n.x.mean(0), n.y.mean(0));  // t = 0 is not in x
  const auto [v1_mean, v1_std] = moments(k.row(3, 1));
  expect_near_rel(n.x.mean(5), v1_mean, "x v1 mean");
  expect_near_rel(n.x.std(5), v1_std, "x v1 std");
  expect_near_rel(n.x.mean(2), 2.0, "dq0 mean");
  expect_near_rel(n.x.mean(3), -1.0, "dq1 mean");
}

TEST(Normalization, FullyConstantGroupGetsStdOne) {
  const Known k;
  const Normalization n = fit_normalization({k.seq}, k.layout);
  // dq0 and dq1 are constant: the group median is 0, the floor too, so std 1.
  EXPECT_EQ(n.x.std(2), 1.0);
  EXPECT_EQ(n.x.std(3), 1.0);

  // A single constant channel is its own group: std 1 as well.
  LogSequence c;
  c.y = Eigen::MatrixXd::Constant(1, 5, 250.0);
  c.u = Eigen::MatrixXd::Constant(1, 5, -3.0);
  const FeatureLayout layout = feature_layout_from_names({"l0"}, {"u0"}, {});
  const Normalization m = fit_normalization({c}, layout);
  EXPECT_EQ(m.y.mean(0), 250.0);
  EXPECT_EQ(m.y.std(0), 1.0);
  EXPECT_EQ(m.u.mean(0), -3.0);
  EXPECT_EQ(m.u.std(0), 1.0);
}

TEST(Normalization, NearlyConstantChannelIsFlooredAtAFractionOfTheGroupMedian) {
  const Known k;
  const Normalization n = fit_normalization({k.seq}, k.layout);
  const auto [v2_mean, v2_std] = moments(k.row(4));
  ASSERT_LT(v2_std, 1e-3);  // the raw std, far below the floor
  // v stds are {20, 100, 4.3e-4}: median 20, floor 0.1 * 20 = 2.
  EXPECT_EQ(kStdFloorOfGroupMedian, 0.1);
  expect_near_rel(n.y.std(4), kStdFloorOfGroupMedian * 20.0, "v2 std floored");
  expect_near_rel(n.y.mean(4), v2_mean, "v2 mean is not affected");
  // Channels above the floor keep their std.
  expect_near_rel(n.y.std(2), 20.0, "v0 std");
  // The floor is per group: q1's std (1.12) is below the v floor (2) but
  // above the q floor (0.1 x 2.24), so it stays.
  expect_near_rel(n.y.std(1), std::sqrt(1.25), "q1 std not floored by v");
  // The same rule on x: v2 over t = 1..3 is {1, 1, 1.001}; the x v-group
  // stds are {18.9, 94.3, 4.7e-4}, median 18.9.
  const auto [x_v0_mean, x_v0_std] = moments(k.row(2, 1));
  expect_near_rel(n.x.std(6), kStdFloorOfGroupMedian * x_v0_std, "x v2 std floored");
}

TEST(Normalization, PoolsEveryStepOfEverySequence) {
  const FeatureLayout layout = feature_layout_from_names({"q0"}, {"u0"}, {});
  LogSequence a, b;
  a.y.resize(1, 2);
  a.y << 0, 0;
  a.u.resize(1, 2);
  a.u << 0, 1;
  b.y.resize(1, 4);
  b.y << 3, 3, 3, 3;
  b.u.resize(1, 4);
  b.u << 0, 1, 0, 1;
  const Normalization n = fit_normalization({a, b}, layout);
  // Pooled over 6 steps: mean 12/6 = 2 (a mean of the two means would be 1.5).
  expect_near_rel(n.y.mean(0), 2.0, "pooled y mean");
  expect_near_rel(n.y.std(0), std::sqrt(2.0), "pooled y std");  // (2*4 + 4*1) / 6
  // x pools t >= 1 only: a contributes 0, b contributes 3, 3, 3.
  expect_near_rel(n.x.mean(0), 9.0 / 4.0, "pooled x mean");
}

TEST(Normalization, NoDataIsAnError) {
  const FeatureLayout layout = feature_layout_from_names({"q0"}, {"u0"}, {});
  EXPECT_THROW(fit_normalization({}, layout), std::invalid_argument);
  LogSequence one;
  one.y = Eigen::MatrixXd::Zero(1, 1);
  one.u = Eigen::MatrixXd::Zero(1, 1);
  EXPECT_THROW(fit_normalization({one}, layout), std::invalid_argument);  // no t >= 1
}

TEST(Normalization, StandardizeAndPhysicalAreInverse) {
  const Known k;
  const Normalization n = fit_normalization({k.seq}, k.layout);
  const Eigen::VectorXd y = k.seq.y.col(2);
  const Eigen::VectorXd s = n.y.standardize(y);
  expect_near_rel(s(0), (5.0 - 4.0) / std::sqrt(5.0), "standardised q0");
  // One division and one multiplication: within 1e-12 relative of the start.
  EXPECT_LT((n.y.physical(s) - y).norm(), kRel * y.norm());
}

}  // namespace
}  // namespace hadynet::trainer::testing
