// Contact detection statistics (docs/method.md, "Detection"; seed paper III-D):
// from N_detect-step prediction errors on contact-free data, the mean mu_e
// and covariance Sigma_e, and d = sqrt((e - mu_e)^T Sigma_e^-1 (e - mu_e)).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/whitening.h"

namespace hadynet::trainer {

// Regularised inverse: Sigma = V diag(l) V^T is inverted with every
// eigenvalue raised to at least kCovarianceFloor * max(l) (and > 0). Channels
// the calibration data never excited (a loadcell that read 0 throughout)
// would otherwise get an (almost) infinite weight in d.
inline constexpr double kCovarianceFloor = 1e-4;
Eigen::MatrixXd regularised_inverse(const Eigen::MatrixXd& covariance);

// Default C_detect: this factor times the 99.9th percentile of d over the
// calibration errors (docs/trainer.md, "Choosing C_detect").
inline constexpr double kThresholdQuantile = 0.999;
inline constexpr double kThresholdMargin = 1.5;

// Calibrates on contact-free sequences with the given PB. The threshold is
// the default rule above unless `threshold` > 0. Throws std::invalid_argument
// if there are fewer errors than 2 x dims.y.
DetectionCalibration calibrate_detection(const HadynetModel& model,
                                         const std::vector<LogSequence>& sequences,
                                         const Eigen::VectorXf& pb, int steps, double threshold,
                                         std::string source);

// d of one error vector (standardised units).
double mahalanobis(const DetectionCalibration& calibration, const Eigen::VectorXd& error);

// d over a log: element j belongs to t = j + 1 + calibration.steps (see
// prediction_errors), with the calibration's PB unless `pb` is given.
Eigen::VectorXd detection_distances(const HadynetModel& model,
                                    const DetectionCalibration& calibration,
                                    const LogSequence& seq, const Eigen::VectorXf& pb = {});

// The q-quantile of `values` by linear interpolation; NaN if empty or q is
// outside [0, 1].
double quantile(std::vector<double> values, double q);

}  // namespace hadynet::trainer
