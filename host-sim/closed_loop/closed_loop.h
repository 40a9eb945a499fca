// Host-sim in closed loop with the MuJoCo hand: the firmware core (build's
// generated model, q15 or f32) runs the grasp stabiliser every 0.2 s on a
// grasp that a scripted disturbance works loose (GraspSession). The seed
// paper's grasp-stabiliser experiment (section IV-E): the evaluation value
// E = h_loss,1 stays flat with the stabiliser and grows without it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "host-sim/plant/disturbance.h"
#include "host-sim/plant/hand_spec.h"
#include "host-sim/replay/replay.h"

namespace hadynet::hostsim {

struct ClosedLoopOptions {
  plant::ObjectKind object = plant::ObjectKind::kCylinder;
  int init_id = 3;           // dynamics state of the grasp (3: not in the paper training set)
  double wear_level = 0.0;
  std::uint64_t seed = 1;    // dataset seed (grasp motion and sensor noise derive from it)
  plant::Disturbance disturbance = plant::default_strike();
  int steps = 100;           // control periods after the grasp
  bool control = true;       // false: hold (u = 0), the firmware only observes
  firmware::Numeric numeric = firmware::Numeric::kQ15;
  std::string pb_state;      // PB table state the stabiliser predicts with ("": the default PB)
  plant::Effects effects;    // plant effects the model may lack (e.g. an input dead time); none by default
  int control_epochs = -1;   // -1: the model's default
  int control_truncation = -1;
  // Ablations of the stabiliser's design choices (grasp_stabilizer.h):
  bool absolute_reference = false;  // the paper's r_k = y_ref instead of relative to holding still
  bool adopt_best_always = false;   // the paper's rule: adopt the best step size even if L rises
  bool all_commands = false;        // let it move every command, not only the model's active ones
};

struct ClosedLoopStep {
  int step = 0;                 // periods since the grasp
  double grasp_error = 0.0;     // E of y_step against y_ref (N^2, beta = 3; plant::grasp_error)
  double force_N = 0.0;         // |disturbance force| during the step that led here
  bool contact = false;         // the firmware's contact flag
  float d = 0.0f;
  std::vector<double> command;  // u applied after this period (physical)
  double loss_initial = 0.0;    // stabiliser's predicted L of its warm start (standardised)
  double loss_final = 0.0;      // predicted L of the adopted sequence
};

struct ClosedLoopRun {
  std::vector<std::string> u_names;
  std::vector<ClosedLoopStep> steps;  // steps + 1 rows: the grasp (y_ref) and every period
  // Mean E over a row range [begin, end).
  double mean_error(std::size_t begin, std::size_t end) const;
};

// Runs one closed loop. Throws std::invalid_argument for an unknown PB state,
// std::runtime_error for a plant without a channel the compiled model reads
// (host-sim/channel_binding.h).
ClosedLoopRun run_closed_loop(const ClosedLoopOptions& options);

}  // namespace hadynet::hostsim
