// The whitening of the detection distance (docs/method.md, "Detection"), as
// codegen writes it for the firmware. Part of the portable deploy-math
// library (hadynet_deploy_math): the same bits on every x86-64.
#pragma once

#include <Eigen/Core>

namespace hadynet::trainer {

// The whitening of the detection distance, as the firmware computes it: for
// the regularised inverse covariance S (symmetric positive definite),
// S = V diag(lambda) V^T and W = diag(sqrt(lambda)) V^T, so W^T W = S and
// d^2 = |W (e - mu)|^2. Eigenvalues ascending; each eigenvector's
// largest-magnitude entry is made positive (deterministic signs). Throws
// std::invalid_argument if S is empty, not square, not finite, not symmetric
// (relative 1e-9) or not positive definite.
Eigen::MatrixXd whitening_matrix(const Eigen::MatrixXd& inverse);

}  // namespace hadynet::trainer
