// The model's output clips (SensorModel::clips, set by `hadynet residual
// --fix` for a saturating sensor): the measured channel cannot exceed its
// rail, so neither may the prediction.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/hadynet_params.h"

namespace hadynet::trainer {

// Clips the rows of physical predictions (y x columns, rows in the model's y
// order) in place.
void apply_output_clips(const HadynetModel& model, Eigen::MatrixXd& y_physical);

// The same clip on standardised network outputs (y x columns), for training
// on the clipped output: clipped elements are set to the rail and their
// entry in `d_y_hat` (the loss gradient, if given, same shape) to 0, since the
// clipped output does not depend on them. Returns the number clipped.
long clip_standardised(const HadynetModel& model, Matrix<float>& y_hat, Matrix<float>* d_y_hat = nullptr);

// Row index and standardised rail of each clip.
struct StandardisedClip {
  Eigen::Index row;
  int side;
  float rail;
};
std::vector<StandardisedClip> standardised_clips(const HadynetModel& model);

}  // namespace hadynet::trainer
