// Contact-detection statistics (trainer/detection.h): the regularised
// inverse, the Mahalanobis distance, quantiles and the calibration.
#include "trainer/detection.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "synthetic_logs.h"
#include "test_batches.h"
#include "trainer/prediction.h"
#include "trainer/training.h"

namespace hadynet::trainer::testing {
namespace {

TEST(RegularisedInverse, EqualsTheInverseOfAWellConditionedMatrix) {
  std::mt19937_64 rng(3);
  const Eigen::MatrixXd a = random_matrix(rng, 5, 5);
  const Eigen::MatrixXd cov = a * a.transpose() + Eigen::MatrixXd::Identity(5, 5);
  // Condition number < 1e2, far from the 1e4 floor: no eigenvalue is raised.
  const Eigen::MatrixXd inv = regularised_inverse(cov);
  const Eigen::MatrixXd exact = cov.inverse();
  // Eigen-decomposition vs LU: both backward stable, the condition number
  // is small, so they agree to ~1e-14 relative; 1e-9 is the stated bound.
  EXPECT_LT((inv - exact).norm(), 1e-9 * exact.norm());
  EXPECT_LT((cov * inv - Eigen::MatrixXd::Identity(5, 5)).norm(), 1e-9);
  EXPECT_LT((inv - inv.transpose()).norm(), 1e-12 * inv.norm());  // symmetric
}

TEST(RegularisedInverse, IsFiniteAndBoundedForSingularMatrices) {
  // Rank 1: v v^T, eigenvalues |v|^2, 0, 0.
  // (Dynamic size: GCC 12 -Warray-bounds misfires on fixed-size 3-vectors
  // inside Eigen's AVX-512 kernels.)
  const Eigen::VectorXd v = Eigen::Vector3d(1.0, 2.0, -2.0);  // |v|^2 = 9
  const Eigen::MatrixXd cov = v * v.transpose();
  const Eigen::MatrixXd inv = regularised_inverse(cov);
  ASSERT_TRUE(inv.allFinite());
  // The floored eigenvalues are kCovarianceFloor * 9, so the largest
  // eigenvalue of the inverse is 1 / (kCovarianceFloor * 9).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(inv);
  const double bound = 1.0 / (kCovarianceFloor * 9.0);
  EXPECT_NEAR(eig.eigenvalues().maxCoeff(), bound, 1e-9 * bound);
  EXPECT_NEAR(eig.eigenvalues().minCoeff(), 1.0 / 9.0, 1e-9);
  // The excited direction is inverted exactly: inv v = v / 9.
  EXPECT_LT((inv * v - v / 9.0).norm(), 1e-9 * bound);

  // An all-zero covariance (errors that never varied) still gives a finite
  // inverse.
  const Eigen::MatrixXd zero_inv = regularised_inverse(Eigen::MatrixXd::Zero(3, 3));
  EXPECT_TRUE(zero_inv.allFinite()) << zero_inv;
}

DetectionCalibration diagonal_calibration() {
  DetectionCalibration c;
  c.steps = 2;
  c.mean = Eigen::Vector3d(0.5, -1.0, 2.0);
  c.covariance = Eigen::Vector3d(4.0, 0.25, 9.0).asDiagonal();
  c.inverse = regularised_inverse(c.covariance);  // cond 36: nothing floored
  c.threshold = 1.0;
  return c;
}

// ---- whitening (the detector's W, written by codegen)

TEST(Whitening, WTransposeWIsTheInverseCovariance) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd a(6, 6);
  for (Eigen::Index i = 0; i < a.size(); ++i) a.data()[i] = normal(rng);
  const Eigen::MatrixXd s = regularised_inverse(a * a.transpose() + 0.1 * Eigen::MatrixXd::Identity(6, 6));
  const Eigen::MatrixXd w = whitening_matrix(s);
  // A backward-stable double eigendecomposition of a 6 x 6 matrix: errors of
  // a few n eps |S|; 1e-12 |S| leaves a margin of ~100.
  EXPECT_LT((w.transpose() * w - s).cwiseAbs().maxCoeff(), 1e-12 * s.cwiseAbs().maxCoeff());
  // Deterministic signs: each row's largest-magnitude entry is positive.
  for (Eigen::Index k = 0; k < w.rows(); ++k) {
    Eigen::Index arg = 0;
    w.row(k).cwiseAbs().maxCoeff(&arg);
    EXPECT_GT(w(k, arg), 0.0);
  }
  // d^2 = |W (e - mu)|^2 = (e - mu)^T S (e - mu) for an arbitrary error
  // (same 1e-12 relative bound).
  const Eigen::VectorXd e = Eigen::VectorXd::LinSpaced(6, -1.0, 2.0);
  const double want = e.dot(s * e);
  EXPECT_NEAR((w * e).squaredNorm(), want, 1e-12 * want);
}

TEST(Whitening, RejectsWhatIsNotSymmetricPositiveDefinite) {
  Eigen::MatrixXd s = Eigen::MatrixXd::Identity(3, 3);
  s(0, 1) = 0.5;  // not symmetric
  EXPECT_THROW(whitening_matrix(s), std::invalid_argument);
  s(1, 0) = 0.5;
  EXPECT_NO_THROW(whitening_matrix(s));
  s(2, 2) = -1.0;  // indefinite
  EXPECT_THROW(whitening_matrix(s), std::invalid_argument);
  EXPECT_THROW(whitening_matrix(Eigen::MatrixXd::Zero(3, 3)), std::invalid_argument);
  EXPECT_THROW(whitening_matrix(Eigen::MatrixXd::Identity(2, 3)), std::invalid_argument);
}

TEST(Mahalanobis, IsZeroAtTheMeanAndCountsStandardDeviations) {
  const DetectionCalibration c = diagonal_calibration();
  const Eigen::Vector3d sigma(2.0, 0.5, 3.0);
  EXPECT_EQ(mahalanobis(c, c.mean), 0.0);
  // A few roundings in the inverse and the quadratic form: 1e-12 relative.
  for (int i = 0; i < 3; ++i) {
    for (const double k : {1.0, -2.5, 4.0}) {
      Eigen::VectorXd e = c.mean;
      e(i) += k * sigma(i);
      EXPECT_NEAR(mahalanobis(c, e), std::abs(k), 1e-12 * std::abs(k)) << "axis " << i;
    }
  }
  // Independent axes add in quadrature: (3, 4) standard deviations -> 5.
  Eigen::VectorXd e = c.mean;
  e(0) += 3.0 * sigma(0);
  e(2) -= 4.0 * sigma(2);
  EXPECT_NEAR(mahalanobis(c, e), 5.0, 1e-12 * 5.0);
}

TEST(Quantile, InterpolatesLinearlyBetweenOrderStatistics) {
  const std::vector<double> v = {3.0, 1.0, 4.0, 2.0};  // sorted 1 2 3 4
  // Positions q * (n - 1) on the sorted values; a handful of roundings.
  EXPECT_DOUBLE_EQ(quantile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(quantile(v, 1.0), 4.0);
  EXPECT_DOUBLE_EQ(quantile(v, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(quantile(v, 0.25), 1.75);
  EXPECT_DOUBLE_EQ(quantile(v, 2.0 / 3.0), 3.0);
  EXPECT_DOUBLE_EQ(quantile(v, 0.9), 3.7);
  EXPECT_DOUBLE_EQ(quantile({7.0}, 0.999), 7.0);
  EXPECT_TRUE(std::isnan(quantile({}, 0.5)));
}

struct CalibrationSetup {
  FeatureLayout layout = spring_layout();
  std::vector<LogSequence> seqs = {spring_sequence(1.0, 25, 61, "none1"),
                                   spring_sequence(1.0, 18, 62, "none2")};
  HadynetModel model = [this] {
    HadynetModel m = new_model(layout, fit_normalization(seqs, layout), {{"none", ""}}, 2, 8, 5, 17);
    m.params = generic_params(m.params.dims, 18).cast<float>();
    return m;
  }();
  Eigen::VectorXf pb = Eigen::Vector2f(0.2f, 0.1f);
};

TEST(CalibrateDetection, StatisticsOfThePredictionErrors) {
  const CalibrationSetup s;
  const int steps = 3;
  const DetectionCalibration c = calibrate_detection(s.model, s.seqs, s.pb, steps, 0.0, "none*.csv");

  Eigen::MatrixXd e(4, 0);
  for (const LogSequence& seq : s.seqs) {
    const Eigen::MatrixXd part = prediction_errors(s.model, seq, s.pb, steps);
    Eigen::MatrixXd joined(4, e.cols() + part.cols());
    joined << e, part;
    e = joined;
  }
  ASSERT_EQ(e.cols(), (25 - 1 - steps) + (18 - 1 - steps));
  EXPECT_EQ(c.samples, e.cols());
  EXPECT_EQ(c.steps, steps);
  EXPECT_EQ(c.pb, s.pb.cast<double>());
  EXPECT_EQ(c.source, "none*.csv");
  // Mean and unbiased covariance, two-pass reference: sums of ~35 O(1)
  // values in a different order, so 1e-12 relative.
  const Eigen::VectorXd mean = e.rowwise().mean();
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(4, 4);
  for (Eigen::Index j = 0; j < e.cols(); ++j) cov += (e.col(j) - mean) * (e.col(j) - mean).transpose();
  cov /= static_cast<double>(e.cols() - 1);
  EXPECT_LT((c.mean - mean).norm(), 1e-12 * mean.norm());
  EXPECT_LT((c.covariance - cov).norm(), 1e-12 * cov.norm());
  EXPECT_EQ(c.inverse, regularised_inverse(c.covariance));

  // Default threshold: margin x the 99.9 % quantile of the calibration's own d.
  std::vector<double> d;
  for (const LogSequence& seq : s.seqs) {
    const Eigen::VectorXd part = detection_distances(s.model, c, seq);
    d.insert(d.end(), part.data(), part.data() + part.size());
  }
  ASSERT_EQ(d.size(), static_cast<std::size_t>(e.cols()));
  const double want = kThresholdMargin * quantile(d, kThresholdQuantile);
  EXPECT_NEAR(c.threshold, want, 1e-12 * want);
  EXPECT_GT(c.threshold, 0.0);

  // An explicit threshold is kept as given.
  EXPECT_EQ(calibrate_detection(s.model, s.seqs, s.pb, steps, 7.5, "").threshold, 7.5);
}

TEST(CalibrateDetection, DistancesUseTheCalibrationPbUnlessGiven) {
  const CalibrationSetup s;
  const DetectionCalibration c = calibrate_detection(s.model, s.seqs, s.pb, 2, 0.0, "");
  const LogSequence& seq = s.seqs[1];
  const Eigen::VectorXd d = detection_distances(s.model, c, seq);
  ASSERT_EQ(d.size(), 18 - 1 - 2);
  const Eigen::MatrixXd e = prediction_errors(s.model, seq, s.pb, 2);
  for (Eigen::Index j = 0; j < d.size(); ++j) EXPECT_EQ(d(j), mahalanobis(c, e.col(j))) << j;
  const Eigen::VectorXf other(Eigen::Vector2f(-1.0f, 1.0f));
  const Eigen::VectorXd d_other = detection_distances(s.model, c, seq, other);
  const Eigen::MatrixXd e_other = prediction_errors(s.model, seq, other, 2);
  EXPECT_EQ(d_other(0), mahalanobis(c, e_other.col(0)));
  EXPECT_NE(d_other, d);
}

TEST(CalibrateDetection, TooFewErrorsIsAnError) {
  const CalibrationSetup s;
  // y has 4 channels: at least 8 errors are needed; T = 10, steps 3 gives 6.
  const std::vector<LogSequence> few = {spring_sequence(1.0, 10, 63, "few")};
  EXPECT_THROW(calibrate_detection(s.model, few, s.pb, 3, 0.0, ""), std::invalid_argument);
  const std::vector<LogSequence> enough = {spring_sequence(1.0, 12, 63, "enough")};  // 8
  EXPECT_NO_THROW(calibrate_detection(s.model, enough, s.pb, 3, 0.0, ""));
}

}  // namespace
}  // namespace hadynet::trainer::testing
