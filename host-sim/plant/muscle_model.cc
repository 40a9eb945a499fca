#include "host-sim/plant/muscle_model.h"

#include <algorithm>

#include "host-sim/plant/hand_geometry.h"

namespace hadynet::plant {
namespace g = geometry;

std::array<double, kMuscles> nominal_muscle_lengths_mm(const JointTargets& q) {
  auto clamp01 = [](double v) { return std::clamp(v, 0.0, 1.0); };
  const double pitch = std::clamp(q.wrist_pitch_rad, -g::kWristPitchRange_rad, g::kWristPitchRange_rad);
  const double yaw = std::clamp(q.wrist_yaw_rad, -g::kWristYawRange_rad, g::kWristYawRange_rad);
  std::array<double, kMuscles> tendon_m{};
  for (int m = 0; m < 3; ++m) tendon_m[m] = g::kWristCoef_m[m][0] * pitch + g::kWristCoef_m[m][1] * yaw;
  // Both branches of a pulley tendon bend alike, so the mean is one finger's.
  auto finger = [&](double s) {
    double sum = 0;
    for (int k = 0; k < 3; ++k) sum -= g::kFingerMomentArm_m[k] * clamp01(s) * g::kFingerRange_rad[k];
    return sum;
  };
  tendon_m[kIndexMiddle] = finger(q.index_middle);
  tendon_m[kRingLittle] = finger(q.ring_little);
  tendon_m[kThumbFlex] = -(g::kThumbFlexMomentArm_m[0] * g::kThumbFlexRange_rad[0] +
                           g::kThumbFlexMomentArm_m[1] * g::kThumbFlexRange_rad[1]) * clamp01(q.thumb_flex);
  tendon_m[kThumbOppose] = -g::kThumbOpposeMomentArm_m * g::kThumbOpposeRange_rad * clamp01(q.thumb_oppose);
  // The presser is the one place the robot compensates the spring it pulls
  // against: the servo must overshoot by spring force / servo gain.
  const double press_m = clamp01(q.stiffness) * g::kPresserTravel_m;
  tendon_m[kStiffness] = -(press_m + g::kPresserSpring_N_per_m * press_m / g::kPresserServo_N_per_m);

  std::array<double, kMuscles> l_mm{};
  for (int m = 0; m < kMuscles; ++m) l_mm[m] = g::kMuscleRestLength_mm + 1000.0 * tendon_m[m];
  for (int m = 0; m < 3; ++m) l_mm[m] -= g::kWristPreload_mm;
  return l_mm;
}

}  // namespace hadynet::plant
