// The model's output clips (SensorModel::clips: a rated range given to
// `hadynet residual`, or a rail `--fix` found for a saturating sensor): the
// measured channel cannot leave them, so neither may the prediction.
//
// A clip bounds the measured channel, y_c = clip_c(g_c(y'_c) + sum k y'_s +
// b_c) (sensor_model.h). On the network's own channel y'_c it is a constant
// bound only where y_c follows from y'_c alone (frame_rail, sensor_model.h): the rail itself for a plain
// or delayed channel, g_c^-1(rail) for a channel with a calibration curve (g
// increases). A cross-talk target or a drifting channel is the frame's value
// plus a term that changes every row, so its clip bounds the measured value
// only (clipping y'_c at the measured rail would forbid the frame the values
// a removed pick-up or bias leaves it: a palm loadcell reading 0.2 of a
// tendon's tension is negative once that is removed).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/hadynet_params.h"

namespace hadynet::trainer {

// Clips the rows of physical model-frame predictions (y x columns, rows in
// the model's y order) in place, at each clip's frame_rail.
void apply_output_clips(const HadynetModel& model, Eigen::MatrixXd& y_physical);

// The same clip on standardised network outputs (y x columns), for training
// on the clipped output: clipped elements are set to the rail and their
// entry in `d_y_hat` (the loss gradient, if given, same shape) to 0, since the
// clipped output does not depend on them. Returns the number clipped.
long clip_standardised(const HadynetModel& model, Matrix<float>& y_hat, Matrix<float>* d_y_hat = nullptr);

// Row index and standardised frame rail of each clip that has one.
struct StandardisedClip {
  Eigen::Index row;
  int side;
  float rail;
};
std::vector<StandardisedClip> standardised_clips(const HadynetModel& model);

}  // namespace hadynet::trainer
