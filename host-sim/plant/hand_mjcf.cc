#include "host-sim/plant/hand_mjcf.h"

#include <locale>
#include <sstream>

#include "host-sim/plant/hand_geometry.h"

namespace hadynet::plant {
namespace g = geometry;

namespace {

struct FingerLayout {
  const char* name;
  double base_y_m;
  std::array<double, 3> length_m;  // proximal, middle, distal phalanx
};
// Palm frame: x from the wrist towards the fingers, z out of the palm.
constexpr FingerLayout kFingers[4] = {
    {"index", -0.027, {0.040, 0.025, 0.020}},
    {"middle", -0.009, {0.045, 0.028, 0.021}},
    {"ring", 0.009, {0.042, 0.026, 0.020}},
    {"little", 0.027, {0.035, 0.021, 0.018}},
};
constexpr const char* kPhalanxJoint[3] = {"mcp", "pip", "dip"};
constexpr double kPalmHalf_m[3] = {0.045, 0.042, 0.010};
constexpr double kFingerBaseX_m = 0.090;

void write_finger(std::ostringstream& x, const FingerLayout& f, const HandSpec& spec) {
  const double scale = spec.wear.spring_stiffness_scale;
  x << "<body name='" << f.name << "_0' pos='" << kFingerBaseX_m << ' ' << f.base_y_m << " 0.002'>\n";
  for (int k = 0; k < 3; ++k) {
    if (k > 0) x << "<body name='" << f.name << '_' << k << "' pos='" << f.length_m[k - 1] << " 0 0'>\n";
    x << "<joint name='" << f.name << '_' << kPhalanxJoint[k] << "' class='finger' range='0 "
      << g::kFingerRange_rad[k] << "' stiffness='" << g::kFingerSpring_Nm_per_rad[k] * scale << "'/>\n";
    const double radius = 0.008 - 0.0005 * k;
    x << "<geom class='hand' type='capsule' fromto='0 0 0 " << f.length_m[k] << " 0 0' size='" << radius
      << "' mass='" << 0.015 - 0.003 * k << "'/>\n";
  }
  x << "<site name='" << f.name << "_tip' type='sphere' pos='" << 0.7 * f.length_m[2] << " 0 0' size='0.013'/>\n";
  x << "</body></body></body>\n";
}

void write_thumb(std::ostringstream& x, const HandSpec& spec) {
  const double scale = spec.wear.spring_stiffness_scale;
  // The thumb lies beside the palm pointing to -y; opposition rolls it up and
  // over the palm, flexion curls it towards the fingers.
  x << "<body name='thumb_0' pos='0.058 -0.046 0.0'>\n"
    << "<joint name='thumb_rot' type='hinge' axis='-1 0 0' range='0 " << g::kThumbOpposeRange_rad
    << "' stiffness='" << 0.12 * scale << "' damping='0.006' armature='0.0001'/>\n"
    << "<geom class='hand' type='capsule' fromto='0 0 0 0.012 -0.035 0' size='0.009' mass='0.02'/>\n"
    << "<body name='thumb_1' pos='0.012 -0.035 0'>\n"
    << "<joint name='thumb_mcp' class='finger' axis='-1 0 0' range='0 " << g::kThumbFlexRange_rad[0]
    << "' stiffness='" << 0.10 * scale << "'/>\n"
    << "<geom class='hand' type='capsule' fromto='0 0 0 0 -0.030 0' size='0.0085' mass='0.012'/>\n"
    << "<body name='thumb_2' pos='0 -0.030 0'>\n"
    << "<joint name='thumb_ip' class='finger' axis='-1 0 0' range='0 " << g::kThumbFlexRange_rad[1]
    << "' stiffness='" << 0.07 * scale << "'/>\n"
    << "<geom class='hand' type='capsule' fromto='0 0 0 0 -0.025 0' size='0.008' mass='0.01'/>\n"
    << "<site name='thumb_tip' type='sphere' pos='0 -0.018 0' size='0.013'/>\n"
    << "</body></body></body>\n";
}

// The object is lightly tied to the palm: three soft slide joints and a roll
// hinge keep it near its place while contacts push it around.
void write_object(std::ostringstream& x, ObjectKind kind) {
  if (kind == ObjectKind::kNone) return;
  const double palm_top = kPalmHalf_m[2];
  double half_height = 0;  // extent of the object below its centre along z
  double x_offset = 0;     // distance of its centre behind the finger bases
  std::ostringstream geoms;
  const char* soft = "";
  switch (kind) {
    case ObjectKind::kHammer:
    case ObjectKind::kHammerSoft: {
      // Handle along y (across the fingers), a steel head off the little-finger side.
      const bool soft_cover = kind == ObjectKind::kHammerSoft;
      const double r = soft_cover ? 0.021 : 0.015;
      half_height = r;
      x_offset = r + 0.006;
      if (soft_cover) soft = " solref='0.03 1' solimp='0.6 0.9 0.008'";
      geoms << "<geom class='object' type='cylinder' size='" << r << " 0.065' euler='1.5708 0 0' mass='"
            << (soft_cover ? 0.13 : 0.10) << "'" << soft << "/>\n"
            << "<geom class='object' type='box' pos='0 0.080 0.0' size='0.016 0.014 0.035' mass='0.30'/>\n";
      break;
    }
    case ObjectKind::kCylinder:
    case ObjectKind::kCylinderLarge: {
      const double r = kind == ObjectKind::kCylinder ? 0.016 : 0.034;
      half_height = r;
      x_offset = r + 0.006;
      geoms << "<geom class='object' type='cylinder' size='" << r << " 0.060' euler='1.5708 0 0' mass='"
            << (kind == ObjectKind::kCylinder ? 0.10 : 0.18) << "'/>\n";
      break;
    }
    case ObjectKind::kGripper:
      // A hand-gripper exerciser: 60 mm wide in the grasp direction.
      half_height = 0.014;
      x_offset = 0.030 + 0.006;
      geoms << "<geom class='object' type='box' size='0.030 0.050 0.014' mass='0.15'/>\n";
      break;
    case ObjectKind::kBall:
      half_height = 0.030;
      x_offset = 0.030 + 0.006;
      geoms << "<geom class='object' type='sphere' size='0.030' mass='0.12'/>\n";
      break;
    case ObjectKind::kNone:
      break;
  }
  x << "<body name='object' pos='" << kFingerBaseX_m - x_offset << " 0 " << palm_top + half_height + 0.0005 << "'>\n"
    << "<joint name='tie_x' type='slide' axis='1 0 0' stiffness='250' damping='2' range='-0.025 0.025'/>\n"
    << "<joint name='tie_y' type='slide' axis='0 1 0' stiffness='250' damping='2' range='-0.025 0.025'/>\n"
    << "<joint name='tie_z' type='slide' axis='0 0 1' stiffness='250' damping='2' range='-0.025 0.025'/>\n"
    << "<joint name='tie_roll' type='hinge' axis='0 1 0' stiffness='0.4' damping='0.01' range='-0.6 0.6'/>\n"
    << geoms.str() << "</body>\n";
}

}  // namespace

std::vector<SpringJoint> finger_spring_joints(const HandSpec& spec) {
  const double scale = spec.wear.spring_stiffness_scale;
  std::vector<SpringJoint> joints;
  for (const auto& f : kFingers)
    for (int k = 0; k < 3; ++k)
      joints.push_back({std::string(f.name) + '_' + kPhalanxJoint[k], g::kFingerSpring_Nm_per_rad[k] * scale});
  joints.push_back({"thumb_mcp", 0.10 * scale});
  joints.push_back({"thumb_ip", 0.07 * scale});
  return joints;
}

std::string hand_mjcf(const HandSpec& spec) {
  std::ostringstream x;
  x.imbue(std::locale::classic());
  x.precision(9);
  const double friction = spec.effects.tendon_friction_N;
  const double servo = spec.wear.servo_stiffness_scale;

  x << "<mujoco model='hadynet_hand'>\n"
    << "<compiler angle='radian' autolimits='true'/>\n"
    << "<option timestep='" << g::kPhysicsStep_s << "' integrator='Euler' gravity='0 0 -9.81'>"
    // The object is a child of the palm body; parent-child contacts must count.
    << "<flag filterparent='disable'/></option>\n"
    << "<default>\n"
    << "  <joint limited='true' damping='0.004' armature='0.0001'/>\n"
    // Hand geoms collide only with the object (contype/conaffinity bits).
    << "  <default class='hand'><geom contype='1' conaffinity='2' friction='0.9 0.005 0.0001'"
       " solref='0.008 1' solimp='0.9 0.95 0.001'/></default>\n"
    << "  <default class='object'><geom contype='2' conaffinity='1' friction='0.9 0.005 0.0001'"
       " solref='0.008 1' solimp='0.9 0.95 0.001'/></default>\n"
    << "  <default class='finger'><joint type='hinge' axis='0 -1 0'/></default>\n"
    << "</default>\n"
    << "<worldbody>\n"
    << "<body name='forearm' pos='0 0 0.3'>\n"
    << "<geom type='capsule' fromto='-0.20 0 0 -0.025 0 0' size='0.03' contype='0' conaffinity='0' mass='1'/>\n"
    << "<body name='wrist'>\n"
    << "<joint name='wrist_pitch' type='hinge' axis='0 -1 0' range='" << -g::kWristPitchRange_rad << ' '
    << g::kWristPitchRange_rad << "' stiffness='0.2' damping='0.05' armature='0.001'/>\n"
    << "<geom type='sphere' size='0.012' mass='0.05' contype='0' conaffinity='0'/>\n"
    << "<body name='hand'>\n"
    << "<joint name='wrist_yaw' type='hinge' axis='0 0 1' range='" << -g::kWristYawRange_rad << ' '
    << g::kWristYawRange_rad << "' stiffness='0.2' damping='0.05' armature='0.001'/>\n"
    << "<geom name='palm' class='hand' type='box' pos='" << kPalmHalf_m[0] << " 0 0' size='" << kPalmHalf_m[0] << ' '
    << kPalmHalf_m[1] << ' ' << kPalmHalf_m[2] << "' mass='0.25'/>\n";
  // Four palm loadcells: quadrant volumes on the palm surface.
  const double qx = kPalmHalf_m[0] / 2, qy = kPalmHalf_m[1] / 2, top = kPalmHalf_m[2];
  const char* palm_sites[4] = {"palm_prox_radial", "palm_prox_ulnar", "palm_dist_radial", "palm_dist_ulnar"};
  for (int i = 0; i < 4; ++i) {
    const double cx = (i < 2 ? 1 : 3) * qx;
    const double cy = (i % 2 == 0 ? -1 : 1) * qy;
    x << "<site name='" << palm_sites[i] << "' type='box' pos='" << cx << ' ' << cy << ' ' << top << "' size='" << qx
      << ' ' << qy << " 0.006'/>\n";
  }
  // The presser that muscle #5 pulls to stiffen the machined springs.
  x << "<body name='presser' pos='0.02 0 -0.014'>\n"
    << "<joint name='press' type='slide' axis='1 0 0' range='0 " << g::kPresserTravel_m << "' stiffness='"
    << g::kPresserSpring_N_per_m << "' damping='15'/>\n"
    << "<geom type='box' size='0.006 0.006 0.002' mass='0.01' contype='0' conaffinity='0'/>\n"
    << "</body>\n";
  for (const auto& f : kFingers) write_finger(x, f, spec);
  write_thumb(x, spec);
  write_object(x, spec.object);
  x << "</body></body></body>\n</worldbody>\n";

  // Muscles as fixed tendons (moment-arm model) with tendon dry friction.
  x << "<tendon>\n";
  for (int m = 0; m < 3; ++m) {
    x << "<fixed name='m" << m << "' frictionloss='" << friction << "'>"
      << "<joint joint='wrist_pitch' coef='" << g::kWristCoef_m[m][0] << "'/>";
    if (g::kWristCoef_m[m][1] != 0.0) x << "<joint joint='wrist_yaw' coef='" << g::kWristCoef_m[m][1] << "'/>";
    x << "</fixed>\n";
  }
  const char* pairs[2][2] = {{"index", "middle"}, {"ring", "little"}};
  for (int p = 0; p < 2; ++p) {
    x << "<fixed name='m" << 3 + p << "' frictionloss='" << friction << "'>";
    for (const char* finger : pairs[p])
      for (int k = 0; k < 3; ++k)
        x << "<joint joint='" << finger << '_' << kPhalanxJoint[k] << "' coef='"
          << -g::kPulleyShare * g::kFingerMomentArm_m[k] << "'/>";
    x << "</fixed>\n";
  }
  x << "<fixed name='m5' frictionloss='" << friction << "'><joint joint='thumb_mcp' coef='"
    << -g::kThumbFlexMomentArm_m[0] << "'/><joint joint='thumb_ip' coef='" << -g::kThumbFlexMomentArm_m[1]
    << "'/></fixed>\n"
    << "<fixed name='m6' frictionloss='" << friction << "'><joint joint='thumb_rot' coef='"
    << -g::kThumbOpposeMomentArm_m << "'/></fixed>\n"
    << "<fixed name='m7' frictionloss='" << friction << "'><joint joint='press' coef='-1'/></fixed>\n"
    << "</tendon>\n";

  // Position-controlled muscles that only pull: force in [-rated, 0];
  // tension = -actuator force.
  x << "<actuator>\n";
  for (int m = 0; m < kMuscles; ++m) {
    const double kp = m < 3 ? g::kWristServo_N_per_m : (m == kStiffness ? g::kPresserServo_N_per_m : g::kFingerServo_N_per_m);
    x << "<position name='m" << m << "' tendon='m" << m << "' kp='" << kp * servo
      << "' ctrllimited='false' forcelimited='true' forcerange='" << -g::kRatedTension_N << " 0'/>\n";
  }
  x << "</actuator>\n<sensor>\n";
  for (int i = 0; i < kLoadcells; ++i) x << "<touch name='lc" << i << "' site='" << kLoadcellNames[i] << "'/>\n";
  x << "</sensor>\n</mujoco>\n";
  return x.str();
}

}  // namespace hadynet::plant
