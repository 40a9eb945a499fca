// The robot's geometric moment-arm model: turns target joint angles into
// target muscle lengths (encoder mm). It knows the nominal moment arms only:
// not the wear, not this initialisation's encoder offsets, not the servo
// error needed to bend the springs. Motions command through it, as on the
// real hand.
#pragma once

#include <array>

#include "host-sim/plant/hand_spec.h"

namespace hadynet::plant {

struct JointTargets {
  double wrist_pitch_rad = 0;  // flexion +, within +-geometry::kWristPitchRange_rad
  double wrist_yaw_rad = 0;    // radial deviation +
  // Flexion as a fraction of each joint's range, 0 (open) .. 1 (closed).
  double index_middle = 0;
  double ring_little = 0;
  double thumb_flex = 0;
  double thumb_oppose = 0;
  double stiffness = 0;  // presser travel fraction, 0 (soft) .. 1 (stiff)
};

std::array<double, kMuscles> nominal_muscle_lengths_mm(const JointTargets& q);

}  // namespace hadynet::plant
