#include "trainer/recognition.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <map>
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

Recognition recognize_object(const HadynetModel& model, const Eigen::VectorXf& pb, double clear_margin) {
  Recognition r;
  r.nearest = nearest_pb(model, pb);
  r.object = model.states[static_cast<std::size_t>(r.nearest.state)].object;
  std::map<std::string, double> best;
  for (std::size_t k = 0; k < model.states.size(); ++k) {
    const std::string& object = model.states[k].object;
    const auto it = best.find(object);
    if (it == best.end() || r.nearest.distances[k] < it->second) best[object] = r.nearest.distances[k];
  }
  r.objects_by_distance.assign(best.begin(), best.end());
  std::stable_sort(r.objects_by_distance.begin(), r.objects_by_distance.end(),
                   [](const auto& a, const auto& b) { return a.second < b.second; });
  if (r.objects_by_distance.size() < 2) {
    r.margin = std::numeric_limits<double>::infinity();
  } else {
    const double d0 = r.objects_by_distance[0].second, d1 = r.objects_by_distance[1].second;
    r.margin = d0 > 0 ? d1 / d0 : std::numeric_limits<double>::infinity();
  }
  r.clear = r.margin >= clear_margin;
  return r;
}

std::vector<Eigen::VectorXf> object_mean_pbs(const HadynetModel& model) {
  std::vector<std::string> order;
  std::map<std::string, std::pair<Eigen::VectorXd, int>> sums;
  for (std::size_t k = 0; k < model.states.size(); ++k) {
    const std::string& object = model.states[k].object;
    const Eigen::VectorXd pb = model.params.pb.row(static_cast<Eigen::Index>(k)).transpose().cast<double>();
    auto [it, inserted] = sums.emplace(object, std::make_pair(Eigen::VectorXd::Zero(pb.size()), 0));
    if (inserted) order.push_back(object);
    it->second.first += pb;
    ++it->second.second;
  }
  std::vector<Eigen::VectorXf> means;
  for (const std::string& object : order) {
    const auto& [sum, n] = sums.at(object);
    means.push_back((sum / n).cast<float>());
  }
  return means;
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
