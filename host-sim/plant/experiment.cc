#include "host-sim/plant/experiment.h"

#include <cmath>
#include <cstdio>

#include "datalog/log_rules.h"
#include "host-sim/plant/hand_geometry.h"
#include "host-sim/plant/rng.h"

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

// The zeroing of a state follows from its name (object, init id: state_id()),
// never from the dataset seed: "Cylinder/i1/w0" is one dynamics state in every
// dataset, so a PB trained for it fits it whatever seed recorded the logs.
// The constant is the dataset seed the zeroings were drawn with before they
// stopped depending on it (1, the paper preset's), so seed-1 data is unchanged.
constexpr std::uint64_t kZeroingSeed = 1;

// Seed of one random stream (motion or sensor noise) of one experiment.
std::uint64_t experiment_seed(const ExperimentSpec& spec, SeedSalt salt) {
  const auto motion_and_init = static_cast<std::uint64_t>(spec.motion) * 1000 + static_cast<std::uint64_t>(spec.init_id);
  return derive_seed(spec.seed, salt, static_cast<std::uint64_t>(spec.object), motion_and_init, wear_key(spec.wear_level));
}
}  // namespace

double to_command_resolution(double mm) {
  return std::round(mm / kCommandResolution_mm) / (1.0 / kCommandResolution_mm);
}

std::uint64_t motion_seed(const ExperimentSpec& spec) { return experiment_seed(spec, kSaltMotion); }
std::uint64_t sensor_noise_seed(const ExperimentSpec& spec) { return experiment_seed(spec, kSaltNoise); }

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
  // Each (object, initialisation) is its own zeroing of the encoders, the same for every dataset seed.
  hand.encoder_offset_mm = encoder_offsets_for(
      spec.init_id, derive_seed(kZeroingSeed, kSaltOffsets, static_cast<std::uint64_t>(spec.object)));
  hand.effects = spec.effects;
  hand.sensor_realism = spec.sensor_realism;
  return hand;
}

ExperimentLoop::ExperimentLoop(const ExperimentSpec& spec)
    : plant_(hand_spec_for(spec)),
      sensors_(spec.effects, spec.sensor_realism, sensor_noise_seed(spec)),
      command_delay_steps_(spec.effects.command_delay_steps) {
  // Start from the open hand, held for 1 s so that the row at t = 0 is at rest.
  target_mm_ = nominal_muscle_lengths_mm(start_pose());
  for (auto& v : target_mm_) v = to_command_resolution(v);
  servo_target_mm_ = target_mm_;
  plant_.settle(target_mm_, 1.0);
  measured_ = sensors_.measure(plant_.state());
}

std::array<double, kMuscles> ExperimentLoop::command_to(const std::array<double, kMuscles>& wanted_mm) const {
  std::array<double, kMuscles> u{};
  for (int m = 0; m < kMuscles; ++m) u[m] = to_command_resolution(wanted_mm[m] - target_mm_[m]);
  return u;
}

std::array<double, kMuscles> ExperimentLoop::apply(const std::array<double, kMuscles>& u_mm) {
  std::array<double, kMuscles> applied{};
  for (int m = 0; m < kMuscles; ++m) {
    applied[m] = to_command_resolution(u_mm[m]);  // unchanged if already at the resolution
    target_mm_[m] += applied[m];
  }
  pending_commands_.push_back(applied);
  if (static_cast<int>(pending_commands_.size()) > command_delay_steps_) {
    for (int m = 0; m < kMuscles; ++m) servo_target_mm_[m] += pending_commands_.front()[m];
    pending_commands_.pop_front();
  }
  plant_.step(servo_target_mm_);
  measured_ = sensors_.measure(plant_.state());
  return applied;
}

ExperimentResult run_experiment(const ExperimentSpec& spec) {
  const HandSpec hand = hand_spec_for(spec);
  ExperimentLoop loop(spec);
  MotionGenerator motion(spec.motion, spec.object, motion_seed(spec));

  datalog::LogTable log;
  auto& meta = log.metadata;
  meta.set("format", "hadynet-log");
  meta.set("format_version", std::to_string(datalog::kFormatVersion));
  meta.set("dt_s", datalog::rules::format_number(g::kControlStep_s));
  meta.set("state", state_id(spec));
  meta.set("object", std::string(object_name(spec.object)));
  meta.set("motion", std::string(motion_name(spec.motion)));
  meta.set("init", std::to_string(spec.init_id));
  meta.set("wear", wear_text(spec.wear_level));
  meta.set("seed", std::to_string(spec.seed));
  meta.set("units", "t=s l=mm f=N fc=N th=rad u=mm");
  // The hand's profile: delta groups (the paper's x; `hadynet train` reads
  // them), loss classes, stabiliser commands, board channels, contact sums.
  datalog::write_profile(hand_profile(), meta);
  meta.set("source", "hadynet collect: MuJoCo hand plant (host-sim/plant)");
  if (spec.declare_effects) meta.set("effects", hand.effects.describe());

  log.columns.push_back("t");
  const auto y_names = observed_channel_names();
  const auto u_names = command_channel_names();
  log.columns.insert(log.columns.end(), y_names.begin(), y_names.end());
  log.columns.insert(log.columns.end(), u_names.begin(), u_names.end());

  std::vector<double> row;
  row.reserve(log.columns.size());
  for (int k = 0; k < spec.steps; ++k) {
    // u_k: change of target applied between t_k and t_k+1, at command resolution.
    const auto u = loop.command_to(motion.next_target());
    row.clear();
    row.push_back(static_cast<double>(k) / (1.0 / g::kControlStep_s));  // 0.6, not 0.6000000000000001
    append_observed(loop.measured(), row);
    row.insert(row.end(), u.begin(), u.end());
    log.append_row(row);
    loop.apply(u);
  }
  return {std::move(log), loop.plant().physics_steps()};
}

std::vector<std::string> observed_channel_names() {
  std::vector<std::string> names;
  for (int m = 0; m < kMuscles; ++m) names.push_back("l" + std::to_string(m));
  for (int m = 0; m < kMuscles; ++m) names.push_back("f" + std::to_string(m));
  for (int i = 0; i < kLoadcells; ++i) names.push_back("fc" + std::to_string(i));
  for (int j = 0; j < kWristJoints; ++j) names.push_back("th" + std::to_string(j));
  return names;
}

datalog::RobotProfile hand_profile() {
  datalog::RobotProfile p;
  p.delta_groups = {"l", "th"};
  p.force_groups = {"f", "fc"};
  p.angle_groups = {"th"};
  p.length_groups = {"l"};
  for (int m = kIndexMiddle; m < kMuscles; ++m) p.control_commands.push_back("u" + std::to_string(m));
  p.board_group = "fc";
  datalog::ContactSum tips{"tips", {}}, palm{"palm", {}};
  for (int i = 0; i < kLoadcells; ++i) (i < kFingertips ? tips : palm).channels.push_back("fc" + std::to_string(i));
  p.contact_sums = {tips, palm};
  return p;
}

std::vector<std::string> command_channel_names() {
  std::vector<std::string> names;
  for (int m = 0; m < kMuscles; ++m) names.push_back("u" + std::to_string(m));
  return names;
}

void append_observed(const Measurement& y, std::vector<double>& out) {
  out.insert(out.end(), y.muscle_length_mm.begin(), y.muscle_length_mm.end());
  out.insert(out.end(), y.tension_N.begin(), y.tension_N.end());
  out.insert(out.end(), y.loadcell_N.begin(), y.loadcell_N.end());
  out.insert(out.end(), y.wrist_rad.begin(), y.wrist_rad.end());
}

}  // namespace hadynet::plant
