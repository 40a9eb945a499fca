// A scripted disturbance on the grasped object, like the seed paper's hammer
// strikes on a table (section IV-E): periodic strikes, each a constant
// external force (and optional torque) on the object for a whole number of
// 0.2 s control steps, plus an optional steady force that grows step by step
// (a slow drift, e.g. the tool being pulled out of the hand).
//
// Units and frames: N and N m, acting at the object's centre of mass
// (HandPlant::set_object_wrench). The vectors are given either in the world
// frame or in the object's radial frame (see DisturbanceFrame); steps count
// from the start of the closed loop (GraspSession::step_index()).
#pragma once

#include <array>
#include <string>
#include <string_view>

namespace hadynet::plant {

struct Wrench {
  std::array<double, 3> force_N{};
  std::array<double, 3> torque_Nm{};
  bool is_zero() const;
};

enum class DisturbanceFrame {
  kWorld,   // world axes: z up, x from the wrist towards the fingers at zero wrist angles
  // Radial frame, taken by GraspSession from the pose at the start of each
  // step (the end of the previous one): x points from the wrist's centre of rotation through the object's
  // centre of mass (outwards), z is world up made perpendicular to x,
  // y = z cross x. A force along x has no moment about the wrist axes, so
  // it loads the grasp but (quasi-statically) not the wrist muscles, which
  // the finger muscles could never compensate; -x pushes the object towards
  // the wrist, out from under the fingers (a hammer: partly along its
  // handle, the way it works loose).
  kRadial,
};

struct Disturbance {
  bool enabled = false;                  // false: no disturbance at all ("none")
  int period_steps = 5;                  // a strike starts every this many steps (>= 1)
  int duration_steps = 1;                // each strike lasts this many steps (1..period)
  int start_step = 5;                    // step index of the first strike (>= 0)
  std::array<double, 3> force_N{};       // strike force (full amplitude)
  std::array<double, 3> torque_Nm{};     // strike torque (full amplitude)
  int ramp_strikes = 0;                  // strike k (0-based) has amplitude min(1, (k+1)/ramp); 0 = full at once
  std::array<double, 3> drift_N_per_step{};  // steady force, grows by this much every step from start_step on
  double drift_max_N = 0;                // cap on the steady force's magnitude; 0 = no cap
  DisturbanceFrame frame = DisturbanceFrame::kWorld;  // frame of force, torque and drift

  // The wrench acting during step `step` (from y_step to y_step+1), in `frame`.
  Wrench at(int step) const;
  // True if a strike acts during `step`.
  bool striking(int step) const;
  // The canonical text, parseable by parse_disturbance ("none" when off).
  std::string describe() const;
};

// The default strike schedule ("strike" with no fields):
//   strike:period=5,duration=1,start=5,force=-8,0,0,ramp=10,frame=radial
// i.e. one 0.2 s strike a second pushing the object towards the wrist,
// growing to 8 N over the first 10 strikes (docs/plant.md: how it was chosen).
Disturbance default_strike();

// Parses a disturbance description:
//   none | off                         no disturbance
//   strike[:FIELD=VALUE,...]           the default schedule with fields changed
// Fields: period=STEPS, duration=STEPS, start=STEP, force=FX,FY,FZ (N),
// torque=TX,TY,TZ (N m), ramp=STRIKES, drift=DX,DY,DZ (N per step),
// drift_max=N, frame=world|radial. Vector values take exactly three
// comma-separated numbers.
// Returns "" on success (and sets `out`), else an error naming the bad field;
// `out` is then unchanged.
std::string parse_disturbance(std::string_view text, Disturbance& out);

}  // namespace hadynet::plant
