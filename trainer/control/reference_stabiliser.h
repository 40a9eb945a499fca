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
// An input dead time's lag input (LaggedInput) is the plan's base command
// `lag` steps earlier, or the command already applied before that; its
// gradient goes to that base command (the firmware's rule).
//
// Everything is in standardised units (trainer/normalization.h).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "trainer/control/loss_weights.h"
#include "trainer/hadynet_model.h"
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

// A lag input (trainer/derived_inputs.h, "lag<d>_<base>") of the plan: at
// horizon step k its value is scale * u(base, k - lag) + offset for
// k >= lag (the map from the base's standardisation to the slot's), and
// history(k) for k < lag (the base command already applied, standardised
// as the slot).
struct LaggedInput {
  int slot = 0, base = 0, lag = 1;
  double scale = 1, offset = 0;
  Eigen::VectorXd history;  // lag entries
};

// The lag inputs of `model` with their maps; the history is the command 0
// (physical), as the firmware's before any command was sent.
std::vector<LaggedInput> lagged_inputs(const HadynetModel& model);

// One planning problem (standardised units).
struct StabiliserProblem {
  Eigen::VectorXd x0;     // initial state x_t
  Eigen::VectorXd pb;     // the PB the network runs with
  Eigen::VectorXd y_now;  // y_t
  Eigen::VectorXd y_ref;  // the reference
  Eigen::VectorXd hold;   // the "no change" command (derived inputs: their value now)
  std::vector<LaggedInput> lagged;
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
