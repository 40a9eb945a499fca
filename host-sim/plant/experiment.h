// One recorded experiment: a dynamics state, a motion and a length in steps,
// run on the plant and returned as a log table (docs/log-format.md).
#pragma once

#include <array>
#include <deque>
#include <cstdint>
#include <string>
#include <vector>

#include "datalog/log_table.h"
#include "datalog/robot_profile.h"
#include "host-sim/plant/hand_plant.h"
#include "host-sim/plant/hand_spec.h"
#include "host-sim/plant/motions.h"
#include "host-sim/plant/sensor_simulation.h"

namespace hadynet::plant {

struct ExperimentSpec {
  ObjectKind object = ObjectKind::kNone;
  Motion motion = Motion::kRandom1;
  int init_id = 0;          // initialisation (encoder zeroing) id
  double wear_level = 0.0;  // 0 new .. 1 worn
  int steps = 500;          // rows in the log (0.2 s each)
  std::uint64_t seed = 1;   // dataset seed: motions and sensor noise (not the zeroing: see state_id)
  Effects effects;          // switchable effects (default: none)
  bool declare_effects = false;  // write the effects into the log metadata
  bool sensor_realism = true;
  std::string split = "train";   // train | test | novel, for the manifest
};

// "Cylinder/i2/w0": the dynamics-state id (object x initialisation x wear).
// It names one dynamics state: the encoder zeroing follows from the object and
// the init id alone, so the same id means the same state under any dataset seed.
std::string state_id(const ExperimentSpec& spec);
// "Cylinder_random1_i2_w0.csv"
std::string log_file_name(const ExperimentSpec& spec);
// The full plant description for a spec (offsets from the object and init id, wear from its level).
HandSpec hand_spec_for(const ExperimentSpec& spec);

struct ExperimentResult {
  datalog::LogTable log;
  long physics_steps = 0;
};
// Runs the experiment. Deterministic: the same spec gives the same log.
ExperimentResult run_experiment(const ExperimentSpec& spec);

// The log's channel names in column order: y = l0..l7, f0..f7, fc0..fc8,
// th0, th1 and u = u0..u7 (docs/log-format.md, docs/plant.md).
std::vector<std::string> observed_channel_names();
std::vector<std::string> command_channel_names();
// The hand's robot profile (datalog/robot_profile.h), written into every
// log: l and th integrate the commands; f, fc are forces, th angles, l
// lengths; the grasp stabiliser moves the finger muscles #1..#5 (u3..u7) and
// holds the wrist muscles (docs/firmware.md: the wrist muscles carry the
// strikes, and letting the stabiliser move them drove grasps away); the
// board scans the loadcells fc0..fc8; tips are fc0..fc4, palm fc5..fc8.
datalog::RobotProfile hand_profile();
// Appends one frame's y values in observed_channel_names() order.
void append_observed(const Measurement& y, std::vector<double>& out);

// Command resolution (mm) of the target muscle lengths.
inline constexpr double kCommandResolution_mm = 0.001;
// Rounds a length (mm) to the command resolution (prints as e.g. -2.991).
double to_command_resolution(double mm);

// Seeds of an experiment's two random streams (motion, sensor noise), derived
// from (seed, object, motion, init, wear) as run_experiment uses them.
std::uint64_t motion_seed(const ExperimentSpec& spec);
std::uint64_t sensor_noise_seed(const ExperimentSpec& spec);

// The plant in the loop exactly as run_experiment drives it: the hand of
// hand_spec_for(spec), settled for 1 s at the open start pose, the sensor
// model seeded from sensor_noise_seed(spec), and the current target muscle
// lengths. GraspSession runs on it too, so that a session and a log agree.
class ExperimentLoop {
 public:
  explicit ExperimentLoop(const ExperimentSpec& spec);

  // The measured y after the last step (log units), i.e. this row's y.
  const Measurement& measured() const { return measured_; }
  // The target muscle lengths the commands sent so far set (the servos
  // follow it Effects::command_delay_steps steps late).
  const std::array<double, kMuscles>& target_mm() const { return target_mm_; }
  // The command that moves the target to `wanted_mm`, at command resolution.
  std::array<double, kMuscles> command_to(const std::array<double, kMuscles>& wanted_mm) const;
  // One 0.2 s step: rounds each u to the command resolution, adds it to the
  // target (no clamping: the servos' 0..200 N force range is the only limit),
  // steps the plant and measures. Returns the u actually applied. With
  // Effects::command_delay_steps = d the servos get the command of d steps
  // earlier (dead time; none before the first command).
  std::array<double, kMuscles> apply(const std::array<double, kMuscles>& u_mm);

  HandPlant& plant() { return plant_; }
  const HandPlant& plant() const { return plant_; }

 private:
  HandPlant plant_;
  SensorSimulation sensors_;
  std::array<double, kMuscles> target_mm_{};
  std::array<double, kMuscles> servo_target_mm_{};           // what the servos hold: target_mm_ d commands ago
  std::deque<std::array<double, kMuscles>> pending_commands_;  // sent, not yet acting (oldest first)
  int command_delay_steps_ = 0;
  Measurement measured_;
};

}  // namespace hadynet::plant
