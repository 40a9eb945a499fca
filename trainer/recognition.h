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

// The object an adapted PB names, and how clearly. The margin is the
// distance to the nearest trained PB of any other object over the distance
// to the recognised one (>= 1; infinite when the model knows one object):
// near 1, a small change of the adapted PB would name another object.
struct Recognition {
  NearestPb nearest;
  std::string object;  // model.states[nearest.state].object
  // Every object of the model with the distance to its nearest trained PB,
  // closest first (the first is `object`).
  std::vector<std::pair<std::string, double>> objects_by_distance;
  double margin = 0;
  bool clear = false;  // margin >= the clear margin asked for
};

// The margin at and above which a recognition is called clear (below:
// ambiguous), chosen on the validation zeroings only (inits 4-6 of dataset
// seed 1; docs/trainer.md, "Recognition over many zeroings", where the
// fresh zeroings' figures are).
inline constexpr double kClearRecognitionMargin = 1.25;

Recognition recognize_object(const HadynetModel& model, const Eigen::VectorXf& pb,
                             double clear_margin = kClearRecognitionMargin);

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
