// One recorded experiment: a dynamics state, a motion and a length in steps,
// run on the plant and returned as a log table (docs/log-format.md).
#pragma once

#include <cstdint>
#include <string>

#include "datalog/log_table.h"
#include "host-sim/plant/hand_spec.h"
#include "host-sim/plant/motions.h"

namespace hadynet::plant {

struct ExperimentSpec {
  ObjectKind object = ObjectKind::kNone;
  Motion motion = Motion::kRandom1;
  int init_id = 0;          // initialisation (encoder zeroing) id
  double wear_level = 0.0;  // 0 new .. 1 worn
  int steps = 500;          // rows in the log (0.2 s each)
  std::uint64_t seed = 1;   // dataset seed; everything else derives from it
  Effects effects;          // switchable effects (default: none)
  bool declare_effects = false;  // write the effects into the log metadata
  bool sensor_realism = true;
  std::string split = "train";   // train | test | novel, for the manifest
};

// "Cylinder/i2/w0": the dynamics-state id (object x initialisation x wear).
std::string state_id(const ExperimentSpec& spec);
// "Cylinder_random1_i2_w0.csv"
std::string log_file_name(const ExperimentSpec& spec);
// The full plant description for a spec (offsets and wear derived from seeds).
HandSpec hand_spec_for(const ExperimentSpec& spec);

struct ExperimentResult {
  datalog::LogTable log;
  long physics_steps = 0;
};
// Runs the experiment. Deterministic: the same spec gives the same log.
ExperimentResult run_experiment(const ExperimentSpec& spec);

// Command resolution (mm) of the target muscle lengths.
inline constexpr double kCommandResolution_mm = 0.001;

}  // namespace hadynet::plant
