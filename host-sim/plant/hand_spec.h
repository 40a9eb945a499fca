// Parameters of one simulated dynamics state of the flexible hand:
// grasped object x initialisation (encoder zero offsets) x wear.
// Everything here is reproducible from (object, init id, wear level); the
// dataset seed only draws motions and sensor noise (experiment.h).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hadynet::plant {

inline constexpr int kMuscles = 8;    // l, f, u dimension
inline constexpr int kLoadcells = 9;  // f_contact dimension
inline constexpr int kWristJoints = 2;

// Muscle order in logs (l0..l7, f0..f7, u0..u7). docs/architecture.md §2 numbers the finger
// muscles #1..#5; they are columns 3..7 here.
enum Muscle : int {
  kWristFlexRadial = 0,  // wrist flexion + radial deviation
  kWristFlexUlnar = 1,   // wrist flexion + ulnar deviation
  kWristExtensor = 2,    // wrist extension
  kIndexMiddle = 3,      // #1: index + middle through a pulley
  kRingLittle = 4,       // #2: ring + little through a pulley
  kThumbFlex = 5,        // #3: thumb flexion
  kThumbOppose = 6,      // #4: thumb opposition (rotation over the palm)
  kStiffness = 7,        // #5: presses the machined springs (stiffens fingers)
};
inline constexpr std::array<int, 4> kFingerMuscles = {kIndexMiddle, kRingLittle, kThumbFlex, kThumbOppose};

// Loadcell order (fc0..fc8): five fingertips, then four palm quadrants.
inline constexpr int kFingertips = 5;
inline constexpr std::array<const char*, kLoadcells> kLoadcellNames = {
    "thumb_tip", "index_tip", "middle_tip", "ring_tip", "little_tip",
    "palm_prox_radial", "palm_prox_ulnar", "palm_dist_radial", "palm_dist_ulnar"};

enum class ObjectKind { kNone, kHammer, kHammerSoft, kCylinder, kGripper, kBall, kCylinderLarge };

// Canonical names used in logs and on the command line.
std::string_view object_name(ObjectKind kind);
std::optional<ObjectKind> parse_object(std::string_view name);
// Every object's canonical name, comma-separated ("None, Hammer, ..."), for
// help texts.
std::string object_list();
// The six training objects of the seed paper, in its order.
inline constexpr std::array<ObjectKind, 6> kPaperObjects = {
    ObjectKind::kNone, ObjectKind::kHammer, ObjectKind::kHammerSoft,
    ObjectKind::kCylinder, ObjectKind::kGripper, ObjectKind::kBall};

// Wear: springs soften, tendons creep (elongate) and become more compliant.
struct Wear {
  double level = 0.0;                 // 0 = new hand, 1 = worn
  double spring_stiffness_scale = 1;  // multiplies every finger spring
  double tendon_elongation_mm = 0;    // added to every finger/wrist tendon
  double servo_stiffness_scale = 1;   // series compliance of the tendon
};
Wear wear_from_level(double level);

// Effects a learned model may lack. Each is off unless enabled; none is ever
// written into a log unless the caller explicitly asks to declare them.
struct Effects {
  // Dry friction on every tendon (N): hysteresis between length and tension.
  double tendon_friction_N = 0.0;
  // Sensor delay: fc channels are reported this many 0.2 s steps late.
  int loadcell_delay_steps = 0;
  // Loadcell drift: bias (N) growing with accumulated load (N*s) plus a slow
  // random walk (N per sqrt(step)), per channel.
  double loadcell_drift_per_Ns = 0.0;
  double loadcell_drift_walk_N = 0.0;
  // Loadcell saturation: a rail (N) below the rated range; <= 0 means off.
  double loadcell_rail_N = 0.0;
  // Cross-talk: each fingertip loadcell picks up this fraction of the
  // neighbouring fingertip's force (thumb<-index, index<-middle, ...).
  double loadcell_crosstalk = 0.0;
  // Cross-talk between groups: the palm loadcell fc6 picks up this fraction
  // of tendon 5's tension (f5, whose cable runs past it), before noise.
  double tension_leak = 0.0;
  // Command dead time: the servos act on each command this many 0.2 s steps
  // after it is sent (ExperimentLoop::apply).
  int command_delay_steps = 0;
  // A static calibration curve: every loadcell reports R (F / R)^exponent of
  // its force F >= 0, R its rated range (50 N); 1 = linear (off). Below 1
  // compressive (0.85: +27 % at 10 N, +80 % at 1 N).
  double loadcell_curve_exponent = 1.0;

  bool any() const;
  // "friction=4,sensor-delay=2" style summary, for declared logs and reports.
  std::string describe() const;
};
// Parses one `--effect` argument: NAME or NAME=VALUE, NAME in
// friction|sensor-delay|drift|saturation|crosstalk|tension-leak|input-delay|sensor-curve. Returns an
// error text or "".
std::string apply_effect_arg(std::string_view arg, Effects& effects);
// The `--effect` option's help: every NAME[=V] with its unit, one line each
// after the first indented by `indent`.
std::string effect_arg_help(const std::string& indent);

// One dynamics state plus its simulation settings.
struct HandSpec {
  ObjectKind object = ObjectKind::kNone;
  int init_id = 0;                   // initialisation (encoder zeroing) id
  Wear wear;
  std::array<double, kMuscles> encoder_offset_mm{};  // per-initialisation zero offsets
  Effects effects;
  bool sensor_realism = true;        // noise, quantisation, rated ranges
};

// Encoder offsets drawn reproducibly from (init_id, seed): uniform +-1.5 mm.
std::array<double, kMuscles> encoder_offsets_for(int init_id, std::uint64_t seed);

}  // namespace hadynet::plant
