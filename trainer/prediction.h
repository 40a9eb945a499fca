// Using a trained HADYNET in physical units: contact simulation (forward
// from a state with a command sequence under any PB) and the N-step
// prediction errors that contact detection is built on.
#pragma once

#include <Eigen/Core>

#include "trainer/hadynet_model.h"
#include "trainer/log_dataset.h"

namespace hadynet::trainer {

// Predicted y_{t+1} .. y_{t+N} (physical units, y x N) from x_t (physical)
// and commands u_t .. u_{t+N-1} (physical, u x N) with PB `pb` (BN eval).
Eigen::MatrixXd simulate(const HadynetModel& model, const Eigen::VectorXd& x0,
                         const Eigen::MatrixXd& u, const Eigen::VectorXf& pb);

// N-step prediction errors over a log: column j is e_t = y_est_t - y_t in
// standardised y units for t = j + 1 + steps, where y_est_t is predicted from
// x_{t-steps} and u_[t-steps, t). (T - 1 - steps columns; none if T is short.)
Eigen::MatrixXd prediction_errors(const HadynetModel& model, const LogSequence& seq,
                                  const Eigen::VectorXf& pb, int steps);

}  // namespace hadynet::trainer
