#include "host-sim/plant/experiment.h"

#include <cmath>
#include <cstdio>

#include "host-sim/plant/hand_geometry.h"
#include "host-sim/plant/hand_plant.h"
#include "host-sim/plant/rng.h"
#include "host-sim/plant/sensor_model.h"

namespace hadynet::plant {
namespace g = geometry;

namespace {
std::string wear_text(double wear) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", wear);
  return buf;
}
std::uint64_t wear_key(double wear) { return static_cast<std::uint64_t>(std::llround(wear * 1000.0)); }
enum SeedSalt : std::uint64_t { kSaltOffsets = 11, kSaltMotion = 12, kSaltNoise = 13 };

// Seed of one random stream (motion or sensor noise) of one experiment.
std::uint64_t experiment_seed(const ExperimentSpec& spec, SeedSalt salt) {
  const auto motion_and_init = static_cast<std::uint64_t>(spec.motion) * 1000 + static_cast<std::uint64_t>(spec.init_id);
  return derive_seed(spec.seed, salt, static_cast<std::uint64_t>(spec.object), motion_and_init, wear_key(spec.wear_level));
}

// Rounds a length (mm) to the command resolution, printing as e.g. -2.991.
double to_command_resolution(double mm) {
  return std::round(mm / kCommandResolution_mm) / (1.0 / kCommandResolution_mm);
}
}  // namespace

std::string state_id(const ExperimentSpec& spec) {
  return std::string(object_name(spec.object)) + "/i" + std::to_string(spec.init_id) + "/w" + wear_text(spec.wear_level);
}

std::string log_file_name(const ExperimentSpec& spec) {
  return std::string(object_name(spec.object)) + "_" + std::string(motion_name(spec.motion)) + "_i" +
         std::to_string(spec.init_id) + "_w" + wear_text(spec.wear_level) + ".csv";
}

HandSpec hand_spec_for(const ExperimentSpec& spec) {
  HandSpec hand;
  hand.object = spec.object;
  hand.init_id = spec.init_id;
  hand.wear = wear_from_level(spec.wear_level);
  // Each (object, initialisation) is its own zeroing of the encoders.
  hand.encoder_offset_mm = encoder_offsets_for(
      spec.init_id, derive_seed(spec.seed, kSaltOffsets, static_cast<std::uint64_t>(spec.object)));
  hand.effects = spec.effects;
  hand.sensor_realism = spec.sensor_realism;
  return hand;
}

ExperimentResult run_experiment(const ExperimentSpec& spec) {
  const HandSpec hand = hand_spec_for(spec);
  HandPlant plant(hand);
  MotionGenerator motion(spec.motion, spec.object, experiment_seed(spec, kSaltMotion));
  SensorModel sensors(hand.effects, hand.sensor_realism, experiment_seed(spec, kSaltNoise));

  datalog::LogTable log;
  auto& meta = log.metadata;
  meta.set("format", "hadynet-log");
  meta.set("format_version", std::to_string(datalog::kFormatVersion));
  meta.set("dt_s", "0.2");
  meta.set("state", state_id(spec));
  meta.set("object", std::string(object_name(spec.object)));
  meta.set("motion", std::string(motion_name(spec.motion)));
  meta.set("init", std::to_string(spec.init_id));
  meta.set("wear", wear_text(spec.wear_level));
  meta.set("seed", std::to_string(spec.seed));
  meta.set("units", "t=s l=mm f=N fc=N th=rad u=mm");
  meta.set("source", "hadynet collect: MuJoCo hand plant (host-sim/plant)");
  if (spec.declare_effects) meta.set("effects", hand.effects.describe());

  log.columns.push_back("t");
  for (int m = 0; m < kMuscles; ++m) log.columns.push_back("l" + std::to_string(m));
  for (int m = 0; m < kMuscles; ++m) log.columns.push_back("f" + std::to_string(m));
  for (int i = 0; i < kLoadcells; ++i) log.columns.push_back("fc" + std::to_string(i));
  for (int j = 0; j < kWristJoints; ++j) log.columns.push_back("th" + std::to_string(j));
  for (int m = 0; m < kMuscles; ++m) log.columns.push_back("u" + std::to_string(m));

  // Start from the open hand, held for 1 s so that the row at t = 0 is at rest.
  std::array<double, kMuscles> target = nominal_muscle_lengths_mm(start_pose());
  for (auto& v : target) v = to_command_resolution(v);
  plant.settle(target, 1.0);
  SensorFrame y = sensors.measure(plant.state());
  std::vector<double> row;
  row.reserve(log.columns.size());
  for (int k = 0; k < spec.steps; ++k) {
    // u_k: change of target applied between t_k and t_k+1, at command resolution.
    const auto wanted = motion.next_target();
    std::array<double, kMuscles> u{};
    for (int m = 0; m < kMuscles; ++m) {
      u[m] = to_command_resolution(wanted[m] - target[m]);
      target[m] += u[m];
    }
    row.clear();
    row.push_back(static_cast<double>(k) / (1.0 / g::kControlStep_s));  // 0.6, not 0.6000000000000001
    row.insert(row.end(), y.muscle_length_mm.begin(), y.muscle_length_mm.end());
    row.insert(row.end(), y.tension_N.begin(), y.tension_N.end());
    row.insert(row.end(), y.loadcell_N.begin(), y.loadcell_N.end());
    row.insert(row.end(), y.wrist_rad.begin(), y.wrist_rad.end());
    row.insert(row.end(), u.begin(), u.end());
    log.append_row(row);
    plant.step(target);
    y = sensors.measure(plant.state());
  }
  return {std::move(log), plant.physics_steps()};
}

}  // namespace hadynet::plant
