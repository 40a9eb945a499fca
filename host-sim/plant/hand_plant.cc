#include "host-sim/plant/hand_plant.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "host-sim/plant/hand_geometry.h"
#include "host-sim/plant/hand_mjcf.h"

namespace hadynet::plant {
namespace g = geometry;

namespace {

// MuJoCo's default handlers write MUJOCO_LOG.TXT into the working folder;
// ours print to stderr only. Fatal errors end the process as MuJoCo expects.
void on_mujoco_warning(const char* msg) { std::fprintf(stderr, "MuJoCo warning: %s\n", msg); }
[[noreturn]] void on_mujoco_error(const char* msg) {
  std::fprintf(stderr, "MuJoCo error: %s\n", msg);
  std::exit(3);
}
void install_mujoco_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_warning = on_mujoco_warning;
    mju_user_error = on_mujoco_error;
  });
}

mjModel* load_from_text(const std::string& xml) {
  install_mujoco_handlers();
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "hadynet_hand.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())) != 0)
    throw std::runtime_error("MuJoCo VFS: cannot allocate the model file");
  const int index = mj_findFileVFS(vfs.get(), name);
  std::memcpy(vfs->filedata[index], xml.data(), xml.size());
  char error[1000] = "";
  mjModel* m = mj_loadXML(name, vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (m == nullptr) throw std::runtime_error(std::string("hand model does not compile: ") + error);
  return m;
}

int require_id(const mjModel* m, mjtObj type, const std::string& name) {
  const int id = mj_name2id(m, type, name.c_str());
  if (id < 0) throw std::runtime_error("hand model lacks '" + name + "'");
  return id;
}

}  // namespace

double servo_target_m(const HandSpec& spec, int muscle, double length_mm) {
  const double elongation_mm = muscle == kStiffness ? 0.0 : spec.wear.tendon_elongation_mm;
  return (length_mm - g::kMuscleRestLength_mm - spec.encoder_offset_mm[muscle] - elongation_mm) / 1000.0;
}

HandPlant::HandPlant(const HandSpec& spec) : spec_(spec) {
  model_ = load_from_text(hand_mjcf(spec));
  data_ = mj_makeData(model_);
  for (int m = 0; m < kMuscles; ++m) {
    const std::string name = "m" + std::to_string(m);
    actuator_id_[m] = require_id(model_, mjOBJ_ACTUATOR, name);
    tendon_id_[m] = require_id(model_, mjOBJ_TENDON, name);
  }
  for (int i = 0; i < kLoadcells; ++i)
    sensor_adr_[i] = model_->sensor_adr[require_id(model_, mjOBJ_SENSOR, "lc" + std::to_string(i))];
  wrist_joint_ = require_id(model_, mjOBJ_JOINT, "wrist_pitch");
  wrist_qpos_adr_[0] = model_->jnt_qposadr[wrist_joint_];
  wrist_qpos_adr_[1] = model_->jnt_qposadr[require_id(model_, mjOBJ_JOINT, "wrist_yaw")];
  press_qpos_adr_ = model_->jnt_qposadr[require_id(model_, mjOBJ_JOINT, "press")];
  if (spec.object != ObjectKind::kNone) object_body_ = require_id(model_, mjOBJ_BODY, "object");
  for (const auto& joint : finger_spring_joints(spec))
    springs_.push_back({require_id(model_, mjOBJ_JOINT, joint.name), joint.stiffness_Nm_per_rad});
  mj_forward(model_, data_);
  // Start from the servo targets that hold the current (zero) pose.
  for (int m = 0; m < kMuscles; ++m)
    target_mm_[m] = data_->ten_length[tendon_id_[m]] * 1000.0 + g::kMuscleRestLength_mm + spec.encoder_offset_mm[m] +
                    (m == kStiffness ? 0.0 : spec.wear.tendon_elongation_mm);
  read_state();
}

HandPlant::~HandPlant() {
  if (data_) mj_deleteData(data_);
  if (model_) mj_deleteModel(model_);
}

double HandPlant::joint_position(const std::string& joint) const {
  return data_->qpos[model_->jnt_qposadr[require_id(model_, mjOBJ_JOINT, joint)]];
}

void HandPlant::set_object_wrench(const std::array<double, 3>& force_N, const std::array<double, 3>& torque_Nm) {
  bool zero = true;
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(force_N[i]) || !std::isfinite(torque_Nm[i]))
      throw std::invalid_argument("object wrench: every component must be finite");
    zero = zero && force_N[i] == 0.0 && torque_Nm[i] == 0.0;
  }
  if (object_body_ < 0) {
    if (!zero) throw std::logic_error("object wrench: the hand holds no object");
    return;
  }
  object_force_N_ = force_N;
  object_torque_Nm_ = torque_Nm;
  // xfrc_applied row of a body: force (3) then torque (3), world frame, at the
  // body's centre of mass. MuJoCo never clears it, so it holds until reset.
  mjtNum* w = data_->xfrc_applied + 6 * object_body_;
  for (int i = 0; i < 3; ++i) {
    w[i] = force_N[i];
    w[3 + i] = torque_Nm[i];
  }
}

std::array<double, 3> HandPlant::object_position_m() const {
  std::array<double, 3> p{};
  if (object_body_ >= 0)
    for (int i = 0; i < 3; ++i) p[i] = data_->xipos[3 * object_body_ + i];
  return p;
}

std::array<double, 3> HandPlant::wrist_centre_m() const {
  std::array<double, 3> p{};
  for (int i = 0; i < 3; ++i) p[i] = data_->xanchor[3 * wrist_joint_ + i];
  return p;
}

void HandPlant::apply_spring_gain() {
  // Muscle #5 presses the machined springs: stiffness grows with presser travel.
  const double travel = std::clamp(data_->qpos[press_qpos_adr_] / g::kPresserTravel_m, 0.0, 1.0);
  const double gain = 1.0 + (g::kMaxSpringGain - 1.0) * travel;
  for (const auto& s : springs_) model_->jnt_stiffness[s.joint_id] = s.stiffness_Nm_per_rad * gain;
}

void HandPlant::substep(const std::array<double, kMuscles>& ctrl_m, bool average_loadcells) {
  for (int m = 0; m < kMuscles; ++m) data_->ctrl[actuator_id_[m]] = ctrl_m[m];
  apply_spring_gain();
  mj_step(model_, data_);
  ++physics_steps_;
  if (data_->warning[mjWARN_BADQACC].number > 0)
    throw std::runtime_error("hand physics diverged (bad acceleration) at t = " + std::to_string(data_->time) + " s");
  if (average_loadcells) {
    for (int i = 0; i < kLoadcells; ++i) loadcell_sum_[i] += data_->sensordata[sensor_adr_[i]];
    ++loadcell_samples_;
  }
}

void HandPlant::settle(const std::array<double, kMuscles>& target_mm, double seconds) {
  std::array<double, kMuscles> ctrl{};
  for (int m = 0; m < kMuscles; ++m) ctrl[m] = servo_target_m(spec_, m, target_mm[m]);
  const int n = static_cast<int>(seconds / g::kPhysicsStep_s);
  loadcell_sum_.fill(0);
  loadcell_samples_ = 0;
  for (int k = 0; k < n; ++k) substep(ctrl, k >= n - g::kLoadcellAverageSubsteps);
  target_mm_ = target_mm;
  read_state();
}

void HandPlant::step(const std::array<double, kMuscles>& target_mm) {
  std::array<double, kMuscles> from{}, to{}, ctrl{};
  for (int m = 0; m < kMuscles; ++m) {
    from[m] = servo_target_m(spec_, m, target_mm_[m]);
    to[m] = servo_target_m(spec_, m, target_mm[m]);
  }
  loadcell_sum_.fill(0);
  loadcell_samples_ = 0;
  for (int k = 1; k <= g::kSubsteps; ++k) {
    const double a = static_cast<double>(k) / g::kSubsteps;
    for (int m = 0; m < kMuscles; ++m) ctrl[m] = from[m] + a * (to[m] - from[m]);
    substep(ctrl, k > g::kSubsteps - g::kLoadcellAverageSubsteps);
  }
  target_mm_ = target_mm;
  read_state();
}

void HandPlant::read_state() {
  for (int m = 0; m < kMuscles; ++m) {
    const double elongation = m == kStiffness ? 0.0 : spec_.wear.tendon_elongation_mm;
    state_.muscle_length_mm[m] = data_->ten_length[tendon_id_[m]] * 1000.0 + g::kMuscleRestLength_mm +
                                 spec_.encoder_offset_mm[m] + elongation;
    state_.tension_N[m] = -data_->actuator_force[actuator_id_[m]];
  }
  for (int i = 0; i < kLoadcells; ++i)
    state_.loadcell_N[i] = loadcell_samples_ > 0 ? loadcell_sum_[i] / loadcell_samples_ : data_->sensordata[sensor_adr_[i]];
  for (int j = 0; j < kWristJoints; ++j) state_.wrist_rad[j] = data_->qpos[wrist_qpos_adr_[j]];
}

}  // namespace hadynet::plant
