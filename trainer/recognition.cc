#include "trainer/recognition.h"

#include <Eigen/Eigenvalues>
#include <stdexcept>

namespace hadynet::trainer {

NearestPb nearest_pb(const HadynetModel& model, const Eigen::VectorXf& pb) {
  const RowMatrix<float>& table = model.params.pb;
  if (pb.size() != table.cols()) throw std::invalid_argument("PB size differs from the model's");
  if (table.rows() == 0) throw std::invalid_argument("the model has no trained PBs");
  NearestPb best;
  for (Eigen::Index k = 0; k < table.rows(); ++k) {
    const double dist =
        (table.row(k).transpose().cast<double>() - pb.cast<double>()).norm();
    best.distances.push_back(dist);
    if (best.state < 0 || dist < best.distance) {
      best.state = static_cast<int>(k);
      best.distance = dist;
    }
  }
  return best;
}

Pca fit_pca(const Eigen::MatrixXd& points, int k) {
  if (points.rows() < 2) throw std::invalid_argument("PCA needs at least 2 points");
  if (k < 1 || k > points.cols()) throw std::invalid_argument("PCA: k outside [1, dim]");
  Pca pca;
  pca.mean = points.colwise().mean().transpose();
  const Eigen::MatrixXd centred = points.rowwise() - pca.mean.transpose();
  const Eigen::MatrixXd cov = centred.transpose() * centred / static_cast<double>(points.rows() - 1);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  const Eigen::Index dim = points.cols();
  pca.axes.resize(dim, k);
  pca.explained.resize(k);
  const double total = std::max(eig.eigenvalues().sum(), 1e-300);
  for (int i = 0; i < k; ++i) {
    const Eigen::Index src = dim - 1 - i;  // eigenvalues ascend
    Eigen::VectorXd axis = eig.eigenvectors().col(src);
    Eigen::Index big = 0;
    axis.cwiseAbs().maxCoeff(&big);
    if (axis(big) < 0) axis = -axis;
    pca.axes.col(i) = axis;
    pca.explained(i) = eig.eigenvalues()(src) / total;
  }
  return pca;
}

}  // namespace hadynet::trainer
