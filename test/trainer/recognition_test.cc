// Object recognition from the PB (trainer/recognition.h): nearest trained
// PB, the two recognition metrics and the PCA map with deterministic axis
// signs.
#include "trainer/recognition.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "synthetic_logs.h"
#include "trainer/training.h"

namespace hadynet::trainer::testing {
namespace {

HadynetModel model_with_pbs(const RowMatrix<float>& pbs) {
  std::vector<PbState> states;
  for (Eigen::Index k = 0; k < pbs.rows(); ++k) states.push_back({"s" + std::to_string(k), ""});
  const FeatureLayout layout = spring_layout();
  HadynetModel m = new_model(layout, fit_normalization({spring_sequence(1.0, 5, 1, "a")}, layout),
                             states, static_cast<int>(pbs.cols()), 8, 5, 1);
  m.params.pb = pbs;
  return m;
}

TEST(NearestPb, PicksTheNearestRowAndReportsEveryDistance) {
  RowMatrix<float> pbs(4, 2);
  pbs << 0.0f, 0.0f,  //
      1.0f, 0.0f,     //
      0.0f, 2.0f,     //
      -1.0f, -1.0f;
  const HadynetModel m = model_with_pbs(pbs);
  const Eigen::Vector2f query(0.75f, 0.5f);
  const NearestPb n = nearest_pb(m, query);
  // Every PB value is dyadic (exact in float) and the distances are computed
  // in double: a sqrt and a few roundings, so 1e-12.
  ASSERT_EQ(n.distances.size(), 4u);
  const double want[] = {std::hypot(0.75, 0.5), std::hypot(0.25, 0.5), std::hypot(0.75, 1.5),
                         std::hypot(1.75, 1.5)};
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(n.distances[static_cast<std::size_t>(k)], want[k], 1e-12) << k;
  EXPECT_EQ(n.state, 1);
  EXPECT_NEAR(n.distance, want[1], 1e-12);

  // Each row is its own nearest PB, at distance 0.
  for (int k = 0; k < 4; ++k) {
    const NearestPb self = nearest_pb(m, pbs.row(k).transpose());
    EXPECT_EQ(self.state, k);
    EXPECT_EQ(self.distance, 0.0);
  }
  EXPECT_EQ(nearest_pb(m, Eigen::Vector2f(-3.0f, -0.5f)).state, 3);
  EXPECT_THROW(nearest_pb(m, Eigen::Vector3f::Zero()), std::invalid_argument);
}

// The margin is the nearest other object's distance over the recognised
// object's: states of one object count once, at their nearest PB.
TEST(RecognizeObject, MarginOverTheNearestOtherObject) {
  RowMatrix<float> pbs(4, 2);
  pbs << 0.0f, 0.0f,  // Ball
      1.0f, 0.0f,     // Ball (a second zeroing)
      0.0f, 2.0f,     // Hammer
      -4.0f, 0.0f;    // None
  HadynetModel m = model_with_pbs(pbs);
  m.states = {{"Ball/i0", "Ball"}, {"Ball/i1", "Ball"}, {"Hammer/i0", "Hammer"}, {"None/i0", "None"}};
  // Near the second Ball PB: 0.25 from it, sqrt(0.75^2 + 2^2) from Hammer.
  const Recognition r =
      recognize_object(m, Eigen::Vector2f(0.75f, 0.0f), kClearRecognitionMargin, RecognitionMetric::kNearestState);
  EXPECT_EQ(r.metric, RecognitionMetric::kNearestState);
  EXPECT_EQ(r.object, "Ball");
  EXPECT_EQ(r.nearest.state, 1);
  ASSERT_EQ(r.objects_by_distance.size(), 3u);
  EXPECT_EQ(r.objects_by_distance[0].first, "Ball");
  EXPECT_EQ(r.objects_by_distance[1].first, "Hammer");
  EXPECT_EQ(r.objects_by_distance[2].first, "None");
  // Dyadic PB values, distances in double: a sqrt and a division, so 1e-12.
  EXPECT_NEAR(r.margin, std::hypot(0.75, 2.0) / 0.25, 1e-12);
  EXPECT_TRUE(r.clear);
  // Half-way between Ball and Hammer (0, 1): both at distance 1, margin 1.
  const auto nearest_state = [&](float a, float b, double clear = kClearRecognitionMargin) {
    return recognize_object(m, Eigen::Vector2f(a, b), clear, RecognitionMetric::kNearestState);
  };
  const Recognition tie = nearest_state(0.0f, 1.0f);
  EXPECT_NEAR(tie.margin, 1.0, 1e-12);
  EXPECT_FALSE(tie.clear) << "margin 1 < the clear margin";
  EXPECT_TRUE(nearest_state(0.0f, 1.0f, 1.0).clear) << "clear from the margin given on";
  EXPECT_TRUE(std::isinf(nearest_state(1.0f, 0.0f).margin)) << "on a trained PB";
}

// The within-object metric: A's two trained PBs lie far apart along x (two
// zeroings moved its PB along x), B's close together, 1.5 above. A query at
// (0, 0.625) sits at A's mean, 3.06 from A's trained PBs but 0.875 from
// B's: the paper's rule names B, the within-object metric A, because along
// x the objects' PBs spread with re-zeroing and along y they do not.
TEST(RecognizeObject, WithinObjectMetricDiscountsTheZeroingSpread) {
  RowMatrix<float> pbs(4, 2);
  pbs << -3.0f, 0.0f,  // A, zeroing 0
      3.0f, 0.0f,      // A, zeroing 1
      0.0f, 1.5f,      // B, zeroing 0
      0.5f, 1.5f;      // B, zeroing 1
  HadynetModel m = model_with_pbs(pbs);
  m.states = {{"A/i0", "A"}, {"A/i1", "A"}, {"B/i0", "B"}, {"B/i1", "B"}};
  const Eigen::Vector2f query(0.0f, 0.625f);
  EXPECT_EQ(recognize_object(m, query, 1.0, RecognitionMetric::kNearestState).object, "B");
  const Recognition r = recognize_object(m, query, 1.0, RecognitionMetric::kWithinObject);
  EXPECT_EQ(r.metric, RecognitionMetric::kWithinObject);
  EXPECT_EQ(r.object, "A");
  EXPECT_EQ(r.nearest.state, 2) << "the nearest trained PB is still reported (Euclidean)";
  // By hand: object means (0, 0) and (0.25, 1.5); pooled within-object
  // covariance over 4 - 2 = 2 degrees of freedom diag((9 + 9 + 1/16 + 1/16) / 2, 0)
  // = diag(9.0625, 0); shrunk by s toward the mean variance 4.53125.
  const double s = kWithinObjectShrinkage, mean_variance = 9.0625 / 2;
  const double vx = (1 - s) * 9.0625 + s * mean_variance, vy = s * mean_variance;
  const double to_a = std::sqrt(0.625 * 0.625 / vy);
  const double to_b = std::sqrt(0.25 * 0.25 / vx + 0.875 * 0.875 / vy);
  ASSERT_EQ(r.objects_by_distance.size(), 2u);
  // Dyadic inputs, a 2x2 Cholesky solve in double: 1e-12.
  EXPECT_NEAR(r.objects_by_distance[0].second, to_a, 1e-12);
  EXPECT_NEAR(r.objects_by_distance[1].second, to_b, 1e-12);
  EXPECT_NEAR(r.margin, to_b / to_a, 1e-12);
  EXPECT_EQ(r.clear, r.margin >= 1.0);
  // The default is this metric with its clear margin.
  const Recognition d = recognize_object(m, query);
  EXPECT_EQ(d.metric, kDefaultRecognitionMetric);
  EXPECT_EQ(d.clear, d.margin >= default_clear_margin(kDefaultRecognitionMetric));
}

// With one trained PB per object there is no within-object spread: the
// within-object metric falls back to the nearest state and says so.
TEST(RecognizeObject, WithoutASpreadTheWithinObjectMetricFallsBackToTheNearestState) {
  RowMatrix<float> pbs(2, 2);
  pbs << 0.0f, 0.0f,  //
      2.0f, 0.0f;
  HadynetModel m = model_with_pbs(pbs);
  m.states = {{"A/i0", "A"}, {"B/i0", "B"}};
  const Recognition r = recognize_object(m, Eigen::Vector2f(0.5f, 0.0f), 1.0, RecognitionMetric::kWithinObject);
  EXPECT_EQ(r.metric, RecognitionMetric::kNearestState);
  EXPECT_EQ(r.object, "A");
  EXPECT_NEAR(r.margin, 1.5 / 0.5, 1e-12);
  RecognitionMetric parsed{};
  EXPECT_TRUE(parse_recognition_metric("within-object", parsed));
  EXPECT_EQ(parsed, RecognitionMetric::kWithinObject);
  EXPECT_TRUE(parse_recognition_metric(metric_name(RecognitionMetric::kNearestState), parsed));
  EXPECT_EQ(parsed, RecognitionMetric::kNearestState);
  EXPECT_FALSE(parse_recognition_metric("mahalanobis", parsed));
}

// Points c + s a + o b for s = -2..2 along a unit direction a, with small
// offsets o along a unit b orthogonal to a. sum(o) = 0 and sum(s o) = 0, so
// the covariance is 2.5 a a^T + 2.5e-4 b b^T exactly: the principal axes are
// a and b, explained 2.5 / (2.5 + 2.5e-4) and 2.5e-4 / (2.5 + 2.5e-4).
const Eigen::Vector3d kCentre(1.0, -2.0, 0.5);
Eigen::MatrixXd points_along(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Eigen::MatrixXd p(5, 3);
  const double offsets[] = {0.01, -0.02, 0.0, 0.02, -0.01};
  for (int i = 0; i < 5; ++i) p.row(i) = (kCentre + (i - 2) * a + offsets[i] * b).transpose();
  return p;
}

TEST(FitPca, FindsTheKnownAxisWithItsSignFixed) {
  const Eigen::Vector3d a(0.6, -0.8, 0.0);  // largest component negative
  const Eigen::Vector3d b(0.0, 0.0, 1.0);
  const Pca pca = fit_pca(points_along(a, b), 2);
  ASSERT_EQ(pca.axes.rows(), 3);
  ASSERT_EQ(pca.axes.cols(), 2);
  ASSERT_EQ(pca.explained.size(), 2);
  EXPECT_LT((pca.mean - kCentre).norm(), 1e-12);
  // Sign rule: the largest-magnitude component is positive, so the axis is -a.
  // Eigenvectors of a 3x3 symmetric matrix with well-separated eigenvalues
  // (gap 2.5 / 2.5e-4) are accurate to ~1e-15 / gap: 1e-9.
  EXPECT_LT((pca.axes.col(0) - (-a)).norm(), 1e-9) << pca.axes;
  EXPECT_LT((pca.axes.col(1) - b).norm(), 1e-9) << pca.axes;
  EXPECT_NEAR(pca.explained(0), 2.5 / (2.5 + 2.5e-4), 1e-9);
  EXPECT_GT(pca.explained(0), 0.9998);
  EXPECT_NEAR(pca.explained(1), 2.5e-4 / (2.5 + 2.5e-4), 1e-9);
  // Orthonormal axes.
  EXPECT_LT((pca.axes.transpose() * pca.axes - Eigen::Matrix2d::Identity()).norm(), 1e-12);
  // Projection: the point at s = +1 lies at -1 on axis 0 (the axis is -a).
  const Eigen::VectorXd proj = pca.project(kCentre + a);
  EXPECT_NEAR(proj(0), -1.0, 1e-9);
  EXPECT_NEAR(proj(1), 0.0, 1e-9);
}

TEST(FitPca, AxisSignFollowsTheLargestComponentForEveryDirection) {
  // Directions with every sign pattern: an eigen-solver returns either sign,
  // so an unfixed sign fails about half of these.
  const Eigen::Vector3d dirs[] = {{0.6, -0.8, 0.0}, {-0.6, 0.8, 0.0}, {0.8, 0.6, 0.0},
                                  {-0.8, -0.6, 0.0}, {0.48, 0.36, -0.8}, {-0.36, 0.8, 0.48},
                                  {0.0, 0.6, 0.8},   {0.0, -0.6, -0.8}};
  for (const Eigen::Vector3d& a : dirs) {
    const Eigen::Vector3d b = a.unitOrthogonal();
    const Pca pca = fit_pca(points_along(a, b), 1);
    Eigen::Index big = 0;
    a.cwiseAbs().maxCoeff(&big);
    const Eigen::Vector3d want = a(big) > 0 ? a : Eigen::Vector3d(-a);
    EXPECT_LT((pca.axes.col(0) - want).norm(), 1e-9) << "a = " << a.transpose();
    // The same points in reverse order give the same map.
    const Pca reversed = fit_pca(points_along(a, b).colwise().reverse(), 1);
    EXPECT_LT((reversed.axes - pca.axes).norm(), 1e-12);
  }
}

TEST(FitPca, RejectsTooFewPointsAndBadK) {
  EXPECT_THROW(fit_pca(Eigen::MatrixXd::Ones(1, 3), 1), std::invalid_argument);
  EXPECT_THROW(fit_pca(Eigen::MatrixXd::Random(4, 3), 0), std::invalid_argument);
  EXPECT_THROW(fit_pca(Eigen::MatrixXd::Random(4, 3), 4), std::invalid_argument);
}

}  // namespace
}  // namespace hadynet::trainer::testing
