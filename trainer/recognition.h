// Object recognition from the PB (seed paper III-C/IV-B): the nearest trained
// PB to an adapted one names the dynamics state and so the grasped object;
// a PCA of the trained PBs gives the 2-D map for plots.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "trainer/hadynet_model.h"

namespace hadynet::trainer {

struct NearestPb {
  int state = -1;                  // row of the PB table
  double distance = 0.0;           // Euclidean, PB units
  std::vector<double> distances;   // to every row
};

NearestPb nearest_pb(const HadynetModel& model, const Eigen::VectorXf& pb);

// How an adapted PB is compared with the trained ones (docs/trainer.md,
// "Recognition over many zeroings").
enum class RecognitionMetric {
  // Euclidean distance to each object's nearest trained PB: the paper's rule.
  kNearestState,
  // Mahalanobis distance to each object's mean trained PB in the trained
  // PBs' pooled within-object covariance S_w (how a re-zeroing moves one
  // object's PB), shrunk toward its mean variance:
  // (1 - s) S_w + s tr(S_w)/p I with s = kWithinObjectShrinkage. Needs an
  // object with two trained PBs; without one, recognize_object uses
  // kNearestState (and says so in Recognition::metric).
  kWithinObject,
};

// Shrinkage of the within-object covariance, chosen on the validation
// zeroings only (inits 4-6 of dataset seed 1: the largest 10th percentile of
// the right object's margin; bench/recognition_metric.py).
inline constexpr double kWithinObjectShrinkage = 0.3;

// "nearest-state" / "within-object" (the CLI's words); parse returns false
// for anything else.
const char* metric_name(RecognitionMetric metric);
bool parse_recognition_metric(const std::string& text, RecognitionMetric& metric);

// The object an adapted PB names, and how clearly. The margin is the
// distance (in the metric) to the nearest other object over the distance to
// the recognised one (>= 1; infinite when the model knows one object): near
// 1, a small change of the adapted PB would name another object.
struct Recognition {
  RecognitionMetric metric = RecognitionMetric::kNearestState;  // the metric used
  NearestPb nearest;   // the nearest trained PB (Euclidean), whatever the metric
  std::string object;  // the recognised object
  // Every object of the model with its distance in the metric, closest
  // first (the first is `object`).
  std::vector<std::pair<std::string, double>> objects_by_distance;
  double margin = 0;
  bool clear = false;  // margin >= the clear margin asked for
};

// The margin at and above which a recognition is called clear (below:
// ambiguous), per metric, chosen on the validation zeroings only (inits 4-6
// of dataset seed 1, as a round value under which about one in ten right
// recognitions there lies; docs/trainer.md, "Recognition over many
// zeroings", where the fresh zeroings' figures are).
inline constexpr double kClearRecognitionMargin = 1.25;        // kNearestState
inline constexpr double kClearWithinObjectMargin = 1.4;        // kWithinObject
double default_clear_margin(RecognitionMetric metric);

// The metric `hadynet recognize` uses unless told otherwise.
inline constexpr RecognitionMetric kDefaultRecognitionMetric = RecognitionMetric::kWithinObject;

Recognition recognize_object(const HadynetModel& model, const Eigen::VectorXf& pb, double clear_margin,
                             RecognitionMetric metric);
// With the default metric and its clear margin.
Recognition recognize_object(const HadynetModel& model, const Eigen::VectorXf& pb);

// The mean trained PB of each object (objects in the order of their first
// state), as starts of a multi-start adaptation (adapt_pb_best_of).
std::vector<Eigen::VectorXf> object_mean_pbs(const HadynetModel& model);


// Principal axes of a point set (rows = points), for 2-D maps.
struct Pca {
  Eigen::VectorXd mean;
  Eigen::MatrixXd axes;        // dim x k, orthonormal columns, by decreasing variance
  Eigen::VectorXd explained;   // fraction of the total variance per axis
  Eigen::VectorXd project(const Eigen::VectorXd& point) const {
    return axes.transpose() * (point - mean);
  }
};

// Throws std::invalid_argument for fewer than 2 points or k > dim.
// Axis signs are fixed so that each axis's largest-magnitude component is
// positive (deterministic maps).
Pca fit_pca(const Eigen::MatrixXd& points, int k);

}  // namespace hadynet::trainer
