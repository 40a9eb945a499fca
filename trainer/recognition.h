// Object recognition from the PB (seed paper III-C/IV-B): the nearest trained
// PB to an adapted one names the dynamics state and so the grasped object;
// a PCA of the trained PBs gives the 2-D map for plots.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "trainer/hadynet_model.h"

namespace hadynet::trainer {

struct NearestPb {
  int state = -1;                  // row of the PB table
  double distance = 0.0;           // Euclidean, PB units
  std::vector<double> distances;   // to every row
};

NearestPb nearest_pb(const HadynetModel& model, const Eigen::VectorXf& pb);


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
