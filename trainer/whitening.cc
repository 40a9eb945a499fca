#include "trainer/whitening.h"

#include <Eigen/Eigenvalues>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace hadynet::trainer {

Eigen::MatrixXd whitening_matrix(const Eigen::MatrixXd& inverse) {
  const auto fail = [](const std::string& what) { throw std::invalid_argument("detection inverse covariance " + what); };
  if (inverse.rows() != inverse.cols() || inverse.rows() == 0) fail("is not a non-empty square matrix");
  if (!inverse.allFinite()) fail("is not finite");
  const double scale = inverse.cwiseAbs().maxCoeff();
  if ((inverse - inverse.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) fail("is not symmetric");
  const Eigen::MatrixXd sym = 0.5 * (inverse + inverse.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(sym);
  if (eig.info() != Eigen::Success) fail("has no eigendecomposition (Eigen failed)");
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  if (!(lambda.minCoeff() > 0)) {
    char smallest[32];
    std::snprintf(smallest, sizeof smallest, "%.4g", lambda.minCoeff());
    fail(std::string("is not positive definite (smallest eigenvalue ") + smallest + ")");
  }
  Eigen::MatrixXd v = eig.eigenvectors();
  for (Eigen::Index k = 0; k < v.cols(); ++k) {
    Eigen::Index arg = 0;
    v.col(k).cwiseAbs().maxCoeff(&arg);
    if (v(arg, k) < 0) v.col(k) = -v.col(k);
  }
  return lambda.cwiseSqrt().asDiagonal() * v.transpose();
}

}  // namespace hadynet::trainer
