// The grasp stabiliser's loss (docs/method.md, "Grasp stabiliser"; seed paper
// III-F): which observed channels it holds to their reference, and with which
// weight. One rule for codegen (the generated kLossClass, kLossWeightUp/Down),
// the trainer-side reference stabiliser (reference_stabiliser.h) and the tests.
//
// The loss over the horizon is L = sum_k sum_i w_i(e) e_ik^2 with e = y_est -
// y_ref in standardised units, w_i = up_i where e >= 0 and down_i where e < 0.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "firmware/core/model_contract.h"

namespace hadynet::trainer::control {

using firmware::LossClass;

// The channel groups of each loss class (trainer::channel_group: "fc3" ->
// "fc"); the hand's profile says f, fc / th / l (datalog/robot_profile.h).
struct LossGroups {
  std::vector<std::string> force, angle, length;
};

// Loss class of each y channel. Throws std::invalid_argument when a group is
// in two classes or names no channel of `y_names`.
std::vector<LossClass> loss_classes(const std::vector<std::string>& y_names, const LossGroups& groups);

// The class weights and the units the loss is computed in.
struct LossRule {
  double beta = 3.0;  // force weight where est < ref (1 where est >= ref): the paper's asymmetry
  double w2 = 1.0;    // angle weight
  double w3 = 1.0;    // length weight
  // Physical (the seed paper's raw sensor values): channel i's class weight
  // is multiplied by std_i^2, so that the standardised error gives the
  // physical one, then every weight is divided by the largest (only the
  // direction of dL/du and the order of losses matter). Standardised: the
  // class weights as given.
  bool physical_units = true;
};

// Per-channel weights of standardised errors (size = classes.size()).
struct LossWeights {
  Eigen::VectorXd up;    // where e >= 0
  Eigen::VectorXd down;  // where e < 0
};

// The weights for `classes` with the y channels' standard deviations
// `y_std` (physical units, > 0). Throws std::invalid_argument when sizes
// differ, or, in physical units, when every weight is zero (nothing to
// minimise).
LossWeights loss_weights(const std::vector<LossClass>& classes, const Eigen::VectorXd& y_std, const LossRule& rule);

}  // namespace hadynet::trainer::control
