// Builds the MJCF (MuJoCo 2.2.2 XML) text of the flexible hand for one
// dynamics state. Names the plant looks up: tendons/actuators m0..m7,
// touch sensors lc0..lc8, joints wrist_pitch, wrist_yaw, press, and the
// finger spring joints listed by finger_spring_joints().
#pragma once

#include <string>
#include <vector>

#include "host-sim/plant/hand_spec.h"

namespace hadynet::plant {

std::string hand_mjcf(const HandSpec& spec);

// Finger/thumb joints whose machined-spring stiffness muscle #5 scales,
// with their unscaled (but wear-scaled) stiffness in N m / rad.
struct SpringJoint {
  std::string name;
  double stiffness_Nm_per_rad;
};
std::vector<SpringJoint> finger_spring_joints(const HandSpec& spec);

}  // namespace hadynet::plant
