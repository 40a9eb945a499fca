// A closed-loop grasp session: the plant side of the grasp stabiliser's
// tests (docs/method.md, "Grasp stabiliser"; seed paper sections III-F, IV-E).
//
// The session builds the hand of one dynamics state exactly as
// run_experiment would (hand_spec_for, ExperimentLoop), settles it, performs
// the grasp phase of that state's Random-2 log (its first kGraspSteps rows,
// same motion seed), and then hands the loop to the caller: y() is the
// measured y in log units, step(u) applies one command row. A scripted
// Disturbance acts on the grasped object during each step.
//
// By default the session then holds the grasp for kDefaultHoldSteps (u = 0,
// no disturbance) so that the reference y_grasp() is at rest.
//
// Correspondence with the log: with hold_steps = 0 and the disturbance off,
// a session of (object, init, wear, seed) is the Random-2 log of the same
// state and seed with its rows re-based: y() after construction is row
// kGraspSteps's y, and after step(u_j) with u_j = the log's u at row
// kGraspSteps + j, y() is row kGraspSteps + j + 1's y, bit for bit (same
// plant, same sensor noise stream). With a hold, the session is that log
// with its first hold_steps rows after the grasp replaced by u = 0 (no
// dataset log has those). The session runs without the switchable sensor
// effects and with sensor realism on (as the paper dataset), unless built
// from an ExperimentSpec that says otherwise.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "host-sim/plant/disturbance.h"
#include "host-sim/plant/experiment.h"

namespace hadynet::plant {

// Steps (0.2 s each) the session holds the grasp (u = 0, no disturbance)
// after the grasp phase, so that y_grasp() is at rest: the last grasp step
// still moves the fingers, and E against that transient would be tens to
// hundreds of N^2 without any disturbance.
inline constexpr int kDefaultHoldSteps = 5;

class GraspSession {
 public:
  GraspSession(ObjectKind object, int init_id, double wear_level, std::uint64_t seed,
               const Disturbance& disturbance = {}, int hold_steps = kDefaultHoldSteps);
  // The same from a full spec (effects, sensor realism); spec.motion and
  // spec.steps are ignored (the grasp is Random-2's). Throws
  // std::invalid_argument for an enabled disturbance without an object or a
  // negative hold.
  GraspSession(const ExperimentSpec& spec, const Disturbance& disturbance, int hold_steps = kDefaultHoldSteps);
  ~GraspSession();
  GraspSession(GraspSession&&) noexcept;
  GraspSession& operator=(GraspSession&&) noexcept;

  // The log's channel names, same strings and order as the log's columns.
  const std::vector<std::string>& y_names() const { return y_names_; }
  const std::vector<std::string>& u_names() const { return u_names_; }

  // The current measured y (log units: mm, N, N, rad).
  const std::vector<double>& y() const { return y_; }
  // y after the grasp and the hold, before the first step: the paper's
  // y_init, the stabiliser's natural y_ref.
  const std::vector<double>& y_grasp() const { return y_grasp_; }

  // One 0.2 s step: u in log units (mm), exactly like a log's u row:
  // each entry is rounded to kCommandResolution_mm and added to the target
  // muscle length (no clamping). The disturbance of step_index() acts during
  // the step. Throws std::invalid_argument if u has the wrong size or a
  // non-finite entry (nothing is changed then); std::runtime_error if the
  // physics diverged (the session is then unusable).
  void step(const std::vector<double>& u);

  // Steps taken by step() (0 right after construction). The current y is
  // row kGraspSteps + hold_steps() + step_index() of the session's
  // Random-2 run (a dataset log's row when hold_steps() == 0).
  int step_index() const { return step_index_; }
  int hold_steps() const { return hold_steps_; }
  // The wrench that acted during the last step, world frame (zero before
  // the first step): for plots.
  const Wrench& last_wrench() const { return last_wrench_; }
  // The wrench the next step will apply, world frame.
  Wrench next_wrench() const { return to_world(disturbance_.at(step_index_)); }
  // The radial frame of DisturbanceFrame::kRadial (unit axes x, y, z in
  // world coordinates) for the next step, from the current pose (the end of
  // the last step, or of the hold). next_wrench() uses it.
  const std::array<std::array<double, 3>, 3>& radial_axes() const { return radial_axes_; }
  // The u actually applied in the last step (after rounding); zeros before.
  const std::vector<double>& last_u() const { return last_u_; }
  const std::array<double, kMuscles>& target_mm() const;

  const Disturbance& disturbance() const { return disturbance_; }
  const ExperimentSpec& spec() const { return spec_; }
  const HandPlant& plant() const;

 private:
  Wrench to_world(const Wrench& w) const;

  ExperimentSpec spec_;
  Disturbance disturbance_;
  std::unique_ptr<ExperimentLoop> loop_;
  std::vector<std::string> y_names_, u_names_;
  std::vector<double> y_, y_grasp_, last_u_;
  Wrench last_wrench_;
  std::array<std::array<double, 3>, 3> radial_axes_{};
  int hold_steps_ = 0;
  int step_index_ = 0;
};

// Grasp error E (seed paper's h_loss,1, the stabiliser's evaluation value)
// in physical units (N^2):
//   E = sum over i in `channels` of w_i (y_i - y_ref_i)^2,
//   w_i = 1 where y_i >= y_ref_i, else beta.
// The weight multiplies the squared difference, as in the firmware's loss
// (firmware/core/grasp_stabilizer.h); the paper's ||w1 . (F - F_ref)||^2
// read literally would square it. Throws std::invalid_argument if y and y_ref
// differ in size or a channel index is out of range.
double grasp_error(const std::vector<double>& y, const std::vector<double>& y_ref, double beta,
                   const std::vector<std::size_t>& channels);

// Indices of the force channels F among `names`: tensions ("f" + digits)
// and/or loadcells ("fc" + digits), in name order.
std::vector<std::size_t> force_channels(const std::vector<std::string>& names, bool tensions = true,
                                        bool loadcells = true);

// E over all of F = (f, f_contact) as docs/method.md, "Grasp stabiliser", defines it, beta = 3.
double grasp_error(const std::vector<double>& y, const std::vector<double>& y_ref,
                   const std::vector<std::string>& names, double beta = 3.0);

}  // namespace hadynet::plant
