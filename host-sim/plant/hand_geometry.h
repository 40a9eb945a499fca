// Geometry and actuation constants of the simulated flexible hand, shared by
// the MJCF builder (hand_mjcf.cc) and the robot-side geometric moment-arm
// model (muscle_model.h). SI units unless a name says otherwise.
#pragma once

#include <array>

namespace hadynet::plant::geometry {

// Moment arms (m) of the finger flexor tendon at MCP, PIP, DIP.
inline constexpr std::array<double, 3> kFingerMomentArm_m = {0.008, 0.006, 0.005};
// Joint ranges (rad) of MCP, PIP, DIP (flexion positive).
inline constexpr std::array<double, 3> kFingerRange_rad = {1.5, 1.7, 1.3};
// Machined-spring stiffness (N m / rad) of MCP, PIP, DIP for a new hand.
inline constexpr std::array<double, 3> kFingerSpring_Nm_per_rad = {0.15, 0.11, 0.09};
// The pulley splits one tendon over two fingers: each branch carries half the
// tension and the muscle length is the mean of the two branch lengths.
inline constexpr double kPulleyShare = 0.5;

// Thumb: opposition (rotation over the palm) and flexion (MCP, IP).
inline constexpr double kThumbOpposeMomentArm_m = 0.010;
inline constexpr double kThumbOpposeRange_rad = 2.0;
inline constexpr std::array<double, 2> kThumbFlexMomentArm_m = {0.007, 0.005};
inline constexpr std::array<double, 2> kThumbFlexRange_rad = {1.2, 1.2};

// Wrist: pitch (flexion +) and yaw (radial deviation +).
inline constexpr double kWristPitchRange_rad = 0.8;
inline constexpr double kWristYawRange_rad = 0.4;
// Fixed-tendon coefficients (m/rad) of the three wrist muscles on (pitch, yaw).
inline constexpr std::array<std::array<double, 2>, 3> kWristCoef_m = {{
    {-0.012, -0.010},  // flexor, radial side
    {-0.012, +0.010},  // flexor, ulnar side
    {+0.016, 0.0},     // extensor
}};
// The robot shortens its wrist length targets by this much (mm) so that the
// antagonistic wrist muscles keep a co-contraction preload.
inline constexpr double kWristPreload_mm = 2.0;

// Stiffness muscle #5: it pulls a presser (slide joint) against a spring;
// the presser's travel scales every finger spring by up to this factor.
inline constexpr double kPresserTravel_m = 0.005;
inline constexpr double kPresserSpring_N_per_m = 3000.0;
inline constexpr double kMaxSpringGain = 3.0;  // springs at full press = 3x

// Muscle rest length (mm) that the encoders report at joint angles 0 and
// zero offset.
inline constexpr double kMuscleRestLength_mm = 250.0;

// Tendon position servo gains (N per m of length error) and rated tension.
inline constexpr double kWristServo_N_per_m = 10000.0;
inline constexpr double kFingerServo_N_per_m = 20000.0;
inline constexpr double kPresserServo_N_per_m = 8000.0;
inline constexpr double kRatedTension_N = 200.0;

// Loadcell rated range (N) and ADC resolution; tension ADC resolution.
inline constexpr double kLoadcellRange_N = 50.0;
inline constexpr int kAdcBits = 12;

// Simulation: physics step and control step.
inline constexpr double kPhysicsStep_s = 0.002;
inline constexpr double kControlStep_s = 0.2;
inline constexpr int kSubsteps = 100;  // kControlStep_s / kPhysicsStep_s
// Loadcells average the contact force over the last this many substeps
// (a 20 ms anti-alias filter).
inline constexpr int kLoadcellAverageSubsteps = 10;

}  // namespace hadynet::plant::geometry
