// The flexible hand as a MuJoCo plant: one dynamics state (HandSpec), driven
// at the 0.2 s control step by target muscle lengths in encoder millimetres,
// returning the true (noise-free) sensor values. Sensor noise and the
// switchable sensor effects are applied afterwards by SensorSimulation.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "host-sim/plant/hand_spec.h"

struct mjModel_;
struct mjData_;

namespace hadynet::plant {

// One sample of every signal the robot measures (y of docs/architecture.md §2).
struct Measurement {
  std::array<double, kMuscles> muscle_length_mm{};  // l: encoder, incl. offsets
  std::array<double, kMuscles> tension_N{};         // f
  std::array<double, kLoadcells> loadcell_N{};      // f_contact
  std::array<double, kWristJoints> wrist_rad{};     // theta: pitch, yaw
};

class HandPlant {
 public:
  // Builds the MJCF for `spec` and loads it. Throws std::runtime_error with
  // MuJoCo's message if the model does not compile.
  explicit HandPlant(const HandSpec& spec);
  ~HandPlant();
  HandPlant(const HandPlant&) = delete;
  HandPlant& operator=(const HandPlant&) = delete;

  // Holds `target_mm` for `seconds` (start-up settling); time is not advanced
  // in the logged clock.
  void settle(const std::array<double, kMuscles>& target_mm, double seconds);
  // One control step (0.2 s): the servo targets ramp linearly from the
  // previous target to `target_mm`. Throws std::runtime_error if the physics
  // diverged.
  void step(const std::array<double, kMuscles>& target_mm);

  // True sensor values at the end of the last step (loadcells averaged over
  // the step's last 20 ms).
  const Measurement& state() const { return state_; }
  const std::array<double, kMuscles>& target_mm() const { return target_mm_; }

  // External wrench on the grasped object's body (MuJoCo mjData::xfrc_applied):
  // force (N) and torque (N m), both in the world frame, acting at the
  // object's centre of mass. World frame: z up (gravity -z); at zero wrist
  // angles x points from the wrist towards the fingers and the palm faces +z,
  // so -z pushes the object into the palm and +z pulls it out of the fingers.
  // The wrench acts on every physics substep until it is set again; it is
  // zero by default. Throws std::logic_error for a nonzero wrench when the
  // hand holds no object (ObjectKind::kNone), std::invalid_argument for a
  // non-finite component.
  void set_object_wrench(const std::array<double, 3>& force_N, const std::array<double, 3>& torque_Nm = {});
  const std::array<double, 3>& object_force_N() const { return object_force_N_; }
  const std::array<double, 3>& object_torque_Nm() const { return object_torque_Nm_; }
  bool has_object() const { return object_body_ >= 0; }
  // Centre of mass of the object (world frame, m); zeros without an object.
  std::array<double, 3> object_position_m() const;
  // The wrist's centre of rotation (the pitch and yaw axes meet there; world
  // frame, m).
  std::array<double, 3> wrist_centre_m() const;
  // Physics steps taken so far (for benchmarks).
  long physics_steps() const { return physics_steps_; }

  // For tests: joint angle by name (rad or m), and the raw model/data.
  double joint_position(const std::string& joint) const;
  const mjModel_* model() const { return model_; }
  const mjData_* data() const { return data_; }

 private:
  void substep(const std::array<double, kMuscles>& ctrl_m, bool average_loadcells);
  void apply_spring_gain();
  void read_state();

  HandSpec spec_;
  mjModel_* model_ = nullptr;
  mjData_* data_ = nullptr;
  std::array<int, kMuscles> actuator_id_{};
  std::array<int, kMuscles> tendon_id_{};
  std::array<int, kLoadcells> sensor_adr_{};
  std::array<int, kWristJoints> wrist_qpos_adr_{};
  int press_qpos_adr_ = -1;
  int object_body_ = -1;  // -1: no object
  int wrist_joint_ = -1;
  std::array<double, 3> object_force_N_{};
  std::array<double, 3> object_torque_Nm_{};
  struct SpringDof {
    int joint_id;
    double stiffness_Nm_per_rad;
  };
  std::vector<SpringDof> springs_;
  std::array<double, kMuscles> target_mm_{};
  std::array<double, kLoadcells> loadcell_sum_{};
  int loadcell_samples_ = 0;
  Measurement state_;
  long physics_steps_ = 0;
};

// Muscle length (encoder mm) -> servo target tendon length (m) for a spec:
// removes the rest length, the encoder offset and the wear elongation.
double servo_target_m(const HandSpec& spec, int muscle, double length_mm);

}  // namespace hadynet::plant
