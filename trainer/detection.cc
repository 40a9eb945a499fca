#include "trainer/detection.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "trainer/prediction.h"

namespace hadynet::trainer {

Eigen::MatrixXd regularised_inverse(const Eigen::MatrixXd& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(covariance);
  if (eig.info() != Eigen::Success) throw std::runtime_error("covariance eigen-decomposition failed");
  // The floor stays a normal positive double: kCovarianceFloor times a tiny
  // (or zero) top eigenvalue would be subnormal or 0, and its inverse inf,
  // which turns the whole inverse into NaN for an all-zero covariance.
  const double lowest = std::max(kCovarianceFloor * eig.eigenvalues().maxCoeff(),
                                 std::numeric_limits<double>::min());
  const Eigen::VectorXd inv_l = eig.eigenvalues().cwiseMax(lowest).cwiseInverse();
  return eig.eigenvectors() * inv_l.asDiagonal() * eig.eigenvectors().transpose();
}

double quantile(std::vector<double> values, double q) {
  if (values.empty() || !(q >= 0.0 && q <= 1.0)) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const double pos = q * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (pos - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

DetectionCalibration calibrate_detection(const HadynetModel& model,
                                         const std::vector<LogSequence>& sequences,
                                         const Eigen::VectorXf& pb, int steps, double threshold,
                                         std::string source) {
  std::vector<Eigen::MatrixXd> parts;
  Eigen::Index n = 0;
  for (const LogSequence& seq : sequences) {
    parts.push_back(prediction_errors(model, seq, pb, steps));
    n += parts.back().cols();
  }
  const Eigen::Index y = model.params.dims.y;
  if (n < 2 * y) {
    throw std::invalid_argument("detection calibration: " + std::to_string(n) +
                                " prediction errors, need at least " + std::to_string(2 * y));
  }
  Eigen::MatrixXd e(y, n);
  Eigen::Index col = 0;
  for (const Eigen::MatrixXd& p : parts) {
    e.middleCols(col, p.cols()) = p;
    col += p.cols();
  }
  DetectionCalibration c;
  c.steps = steps;
  c.pb = pb.cast<double>();
  c.mean = e.rowwise().mean();
  const Eigen::MatrixXd centred = e.colwise() - c.mean;
  c.covariance = centred * centred.transpose() / static_cast<double>(n - 1);
  c.inverse = regularised_inverse(c.covariance);
  c.samples = static_cast<long>(n);
  c.source = std::move(source);
  c.threshold = 1.0;  // placeholder so mahalanobis() can run below
  if (threshold > 0) {
    c.threshold = threshold;
  } else {
    std::vector<double> d(static_cast<std::size_t>(n));
    for (Eigen::Index j = 0; j < n; ++j) d[static_cast<std::size_t>(j)] = mahalanobis(c, e.col(j));
    c.threshold = kThresholdMargin * quantile(std::move(d), kThresholdQuantile);
  }
  return c;
}

double mahalanobis(const DetectionCalibration& calibration, const Eigen::VectorXd& error) {
  const Eigen::VectorXd r = error - calibration.mean;
  return std::sqrt(std::max(0.0, r.dot(calibration.inverse * r)));
}

Eigen::VectorXd detection_distances(const HadynetModel& model,
                                    const DetectionCalibration& calibration,
                                    const LogSequence& seq, const Eigen::VectorXf& pb) {
  const Eigen::VectorXf p = pb.size() != 0 ? pb : calibration.pb.cast<float>();
  const Eigen::MatrixXd e = prediction_errors(model, seq, p, calibration.steps);
  Eigen::VectorXd d(e.cols());
  for (Eigen::Index j = 0; j < e.cols(); ++j) d(j) = mahalanobis(calibration, e.col(j));
  return d;
}

}  // namespace hadynet::trainer
