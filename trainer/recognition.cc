#include "trainer/recognition.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
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

const char* metric_name(RecognitionMetric metric) {
  return metric == RecognitionMetric::kWithinObject ? "within-object" : "nearest-state";
}

bool parse_recognition_metric(const std::string& text, RecognitionMetric& metric) {
  if (text == "nearest-state") {
    metric = RecognitionMetric::kNearestState;
  } else if (text == "within-object") {
    metric = RecognitionMetric::kWithinObject;
  } else {
    return false;
  }
  return true;
}

double default_clear_margin(RecognitionMetric metric) {
  return metric == RecognitionMetric::kWithinObject ? kClearWithinObjectMargin : kClearRecognitionMargin;
}

namespace {

// Each object's mean trained PB (double), objects in the order of their
// first state: the within-object metric's centres and the multi-start
// adaptation's starts (object_mean_pbs).
struct ObjectMeans {
  std::vector<std::string> objects;
  std::vector<Eigen::VectorXd> means;
  const Eigen::VectorXd& mean_of(const std::string& object) const {
    return means[static_cast<std::size_t>(std::find(objects.begin(), objects.end(), object) - objects.begin())];
  }
};

ObjectMeans object_means(const HadynetModel& model) {
  ObjectMeans out;
  std::vector<int> counts;
  for (std::size_t k = 0; k < model.states.size(); ++k) {
    const std::string& object = model.states[k].object;
    const Eigen::VectorXd pb = model.params.pb.row(static_cast<Eigen::Index>(k)).transpose().cast<double>();
    const auto it = std::find(out.objects.begin(), out.objects.end(), object);
    if (it == out.objects.end()) {
      out.objects.push_back(object);
      out.means.push_back(pb);
      counts.push_back(1);
    } else {
      const auto i = static_cast<std::size_t>(it - out.objects.begin());
      out.means[i] += pb;
      ++counts[i];
    }
  }
  for (std::size_t i = 0; i < out.means.size(); ++i) out.means[i] /= static_cast<double>(counts[i]);
  return out;
}

// Each object's distance to pb in the within-object metric, in the order of
// the objects' first states; empty when no object has two trained PBs.
std::vector<std::pair<std::string, double>> within_object_distances(const HadynetModel& model,
                                                                    const Eigen::VectorXd& pb) {
  const RowMatrix<float>& table = model.params.pb;
  const ObjectMeans means = object_means(model);
  const Eigen::Index dof = table.rows() - static_cast<Eigen::Index>(means.objects.size());
  if (dof < 1) return {};
  // Pooled within-object covariance, then shrunk toward its mean variance.
  Eigen::MatrixXd within = Eigen::MatrixXd::Zero(table.cols(), table.cols());
  for (std::size_t k = 0; k < model.states.size(); ++k) {
    const Eigen::VectorXd d =
        table.row(static_cast<Eigen::Index>(k)).transpose().cast<double>() - means.mean_of(model.states[k].object);
    within += d * d.transpose();
  }
  within /= static_cast<double>(dof);
  const double s = kWithinObjectShrinkage;
  const double mean_variance = within.trace() / static_cast<double>(within.rows());
  if (!(mean_variance > 0)) return {};  // every object's PBs coincide: no spread to measure
  const Eigen::MatrixXd shrunk =
      (1 - s) * within + s * mean_variance * Eigen::MatrixXd::Identity(within.rows(), within.cols());
  const Eigen::LLT<Eigen::MatrixXd> llt(shrunk);  // positive definite: s > 0 and mean_variance > 0
  std::vector<std::pair<std::string, double>> out;
  for (std::size_t i = 0; i < means.objects.size(); ++i) {
    const Eigen::VectorXd d = pb - means.means[i];
    out.emplace_back(means.objects[i], std::sqrt(std::max(0.0, d.dot(llt.solve(d)))));
  }
  return out;
}

}  // namespace

Recognition recognize_object(const HadynetModel& model, const Eigen::VectorXf& pb, double clear_margin,
                             RecognitionMetric metric) {
  Recognition r;
  r.nearest = nearest_pb(model, pb);
  if (metric == RecognitionMetric::kWithinObject) {
    r.objects_by_distance = within_object_distances(model, pb.cast<double>());
  }
  if (!r.objects_by_distance.empty()) {
    r.metric = RecognitionMetric::kWithinObject;
  } else {
    r.metric = RecognitionMetric::kNearestState;
    std::map<std::string, double> best;
    for (std::size_t k = 0; k < model.states.size(); ++k) {
      const std::string& object = model.states[k].object;
      const auto it = best.find(object);
      if (it == best.end() || r.nearest.distances[k] < it->second) best[object] = r.nearest.distances[k];
    }
    r.objects_by_distance.assign(best.begin(), best.end());
  }
  std::stable_sort(r.objects_by_distance.begin(), r.objects_by_distance.end(),
                   [](const auto& a, const auto& b) { return a.second < b.second; });
  // Nearest state: its object (the paper's rule; first among equal
  // distances); within-object: the nearest object mean.
  r.object = r.metric == RecognitionMetric::kNearestState
                 ? model.states[static_cast<std::size_t>(r.nearest.state)].object
                 : r.objects_by_distance.front().first;
  if (r.objects_by_distance.size() < 2) {
    r.margin = std::numeric_limits<double>::infinity();
  } else {
    const double d0 = r.objects_by_distance[0].second, d1 = r.objects_by_distance[1].second;
    r.margin = d0 > 0 ? d1 / d0 : std::numeric_limits<double>::infinity();
  }
  r.clear = r.margin >= clear_margin;
  return r;
}

Recognition recognize_object(const HadynetModel& model, const Eigen::VectorXf& pb) {
  return recognize_object(model, pb, default_clear_margin(kDefaultRecognitionMetric), kDefaultRecognitionMetric);
}

std::vector<Eigen::VectorXf> object_mean_pbs(const HadynetModel& model) {
  std::vector<Eigen::VectorXf> out;
  for (const Eigen::VectorXd& mean : object_means(model).means) out.push_back(mean.cast<float>());
  return out;
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
