// The grasp stabiliser's optimiser (docs/method.md, "Grasp stabiliser"; seed
// paper III-F) on the trainer's double network: the reference the firmware's
// fixed-point GraspStabilizer (firmware/core/grasp_stabilizer.h) is checked
// against (test/firmware/roundtrip_test.cc). One planning period:
//
//   u (horizon steps) starts at "hold" (no change); references relative to
//   holding still, r_k = y_ref + y_hold,k - y_t (the firmware's default);
//   each epoch: g = dL/du by BPTT (truncated to `truncation` steps), zero for
//   the commands the stabiliser holds, unit direction g/|g|; try each step
//   size alpha_a: u - alpha_a g/|g|, and keep the one that lowers L most
//   (none: stop). The command adopted is the first step of u.
//
// Everything is in standardised units (trainer/normalization.h).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "trainer/control/loss_weights.h"
#include "trainer/hadynet_params.h"

namespace hadynet::trainer::control {

// The firmware's settings (generated kControl* constants).
struct StabiliserSettings {
  int horizon = 8;                // N_control
  int epochs = 3;                 // N_epoch
  int truncation = 8;             // K; >= horizon: full BPTT
  std::vector<double> alphas;     // step sizes, L2 norm of the whole command sequence's step
  std::vector<bool> active;       // per u channel: may the stabiliser change it
};

// One planning problem (standardised units).
struct StabiliserProblem {
  Eigen::VectorXd x0;     // initial state x_t
  Eigen::VectorXd pb;     // the PB the network runs with
  Eigen::VectorXd y_now;  // y_t
  Eigen::VectorXd y_ref;  // the reference
  Eigen::VectorXd hold;   // the "no change" command
};

struct StabiliserPlan {
  Eigen::VectorXd direction;  // the first epoch's g/|g|, step-major (k * U + i)
  Eigen::VectorXd command;    // the adopted u_t
  int alpha = -1;             // the last epoch's best step size (-1: none lowered L)
};

// Throws std::invalid_argument on sizes that do not match the parameters.
StabiliserPlan reference_plan(const HadynetParams<double>& params, const StabiliserProblem& problem,
                              const LossWeights& weights, const StabiliserSettings& settings);

}  // namespace hadynet::trainer::control
