// Physical plausibility of the MuJoCo hand plant. Each test runs the noise-free
// plant (true sensor values) through a scripted grasp and checks a bound that
// a real flexible hand satisfies; the bounds are stated with their reason.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <numeric>

#include "host-sim/plant/hand_plant.h"
#include "host-sim/plant/muscle_model.h"

namespace hadynet::plant {
namespace {

HandSpec spec_for(ObjectKind object) {
  HandSpec spec;
  spec.object = object;
  spec.sensor_realism = false;
  return spec;
}

// Closes index-middle and ring-little to `close` (fraction of range) over
// `steps` control steps, thumb half-way, from the open start pose.
JointTargets grasp_pose(double close, double stiffness = 0.0, double thumb = 0.5) {
  JointTargets q;
  q.index_middle = q.ring_little = close;
  q.thumb_flex = q.thumb_oppose = thumb;
  q.stiffness = stiffness;
  return q;
}

double sum(const std::array<double, kLoadcells>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

// Contacts between the object and the four long fingers (not palm, not thumb).
int finger_object_contacts(const HandPlant& plant) {
  const mjModel* m = plant.model();
  const mjData* d = plant.data();
  const int object = mj_name2id(m, mjOBJ_BODY, "object");
  auto is_long_finger = [&](int geom) {
    const std::string body = mj_id2name(m, mjOBJ_BODY, m->geom_bodyid[geom]);
    for (const char* f : {"index_", "middle_", "ring_", "little_"})
      if (body.rfind(f, 0) == 0) return true;
    return false;
  };
  int n = 0;
  for (int i = 0; i < d->ncon; ++i) {
    const auto& c = d->contact[i];
    if ((m->geom_bodyid[c.geom1] == object && is_long_finger(c.geom2)) ||
        (m->geom_bodyid[c.geom2] == object && is_long_finger(c.geom1)))
      ++n;
  }
  return n;
}

TEST(HandPlantPlausibility, GraspingAnyObjectRaisesLoadcellsOverNone) {
  // Same command for every object: close to 95 % of range in 10 steps, hold 5.
  auto grasp_loadcell_sum = [](ObjectKind object) {
    HandPlant plant(spec_for(object));
    plant.settle(nominal_muscle_lengths_mm(grasp_pose(0.05)), 1.0);
    for (int k = 1; k <= 10; ++k) plant.step(nominal_muscle_lengths_mm(grasp_pose(0.05 + 0.09 * k)));
    for (int k = 0; k < 5; ++k) plant.step(nominal_muscle_lengths_mm(grasp_pose(0.95)));
    return sum(plant.state().loadcell_N);
  };
  const double none = grasp_loadcell_sum(ObjectKind::kNone);
  // Without an object no geom can touch a loadcell: exactly zero.
  EXPECT_EQ(none, 0.0);
  for (ObjectKind object : {ObjectKind::kHammer, ObjectKind::kHammerSoft, ObjectKind::kCylinder,
                            ObjectKind::kGripper, ObjectKind::kBall, ObjectKind::kCylinderLarge}) {
    // A grasp presses the object with several newtons; 1 N is far above
    // the ADC resolution (12 mN) and below every object's weight + grip.
    EXPECT_GT(grasp_loadcell_sum(object), none + 1.0) << object_name(object);
  }
}

TEST(HandPlantPlausibility, TensionRisesWhenShorteningAgainstAnObject) {
  // Shorten muscle #1 (index+middle) step by step; with a cylinder in the
  // way its tension must keep rising and end well above the free hand's.
  auto tensions = [](ObjectKind object) {
    HandPlant plant(spec_for(object));
    plant.settle(nominal_muscle_lengths_mm(grasp_pose(0.6)), 1.0);
    std::vector<double> f;
    for (int k = 0; k <= 8; ++k) {
      plant.step(nominal_muscle_lengths_mm(grasp_pose(0.6 + 0.05 * k)));
      plant.step(nominal_muscle_lengths_mm(grasp_pose(0.6 + 0.05 * k)));
      f.push_back(plant.state().tension_N[kIndexMiddle]);
    }
    return f;
  };
  const auto free_hand = tensions(ObjectKind::kNone);
  const auto blocked = tensions(ObjectKind::kCylinder);
  // Monotonic within 0.5 N (contact settling jitter); the last shortening
  // steps must add > 10 N over the free hand (servo gain 20 N/mm x a few mm
  // the object prevents).
  for (std::size_t i = 1; i < blocked.size(); ++i) EXPECT_GT(blocked[i], blocked[i - 1] - 0.5) << "step " << i;
  EXPECT_GT(blocked.back() - free_hand.back(), 10.0);
}

TEST(HandPlantPlausibility, SoftCoveredHammerIsTouchedEarlierInAGrasp) {
  // Hammer-S has a thicker (soft) handle, so closing fingers meet it sooner.
  // The thumb stays open so that only the four closing fingers can touch.
  auto first_contact_step = [](ObjectKind object) {
    HandPlant plant(spec_for(object));
    plant.settle(nominal_muscle_lengths_mm(grasp_pose(0.05, 0.0, 0.05)), 1.0);
    for (int k = 1; k <= 60; ++k) {
      plant.step(nominal_muscle_lengths_mm(grasp_pose(0.05 + 0.016 * k, 0.0, 0.05)));
      if (finger_object_contacts(plant) > 0) return k;
    }
    return 1000;
  };
  const int soft = first_contact_step(ObjectKind::kHammerSoft);
  const int hard = first_contact_step(ObjectKind::kHammer);
  EXPECT_LT(soft, 1000);
  EXPECT_LT(hard, 1000);
  // At least one closing step (1.6 % of range) earlier.
  EXPECT_LT(soft, hard);
}

TEST(HandPlantPlausibility, StiffnessMuscleMakesFingersStiffer) {
  // Same finger command, presser released vs fully pulled by muscle #5.
  auto hold = [](double stiffness) {
    HandPlant plant(spec_for(ObjectKind::kNone));
    plant.settle(nominal_muscle_lengths_mm(grasp_pose(0.6, stiffness)), 2.0);
    return std::pair{plant.state().tension_N[kIndexMiddle], plant.joint_position("index_mcp")};
  };
  const auto [soft_tension, soft_angle] = hold(0.0);
  const auto [stiff_tension, stiff_angle] = hold(1.0);
  // Springs up to 3x stiffer at full press: holding the same tendon length
  // takes clearly more tension (> 1.5x) and the finger bends less.
  EXPECT_GT(stiff_tension, 1.5 * soft_tension);
  EXPECT_LT(stiff_angle, soft_angle);
}

TEST(HandPlantPlausibility, WristFollowsItsMuscles) {
  // Commanding wrist flexion (+0.4 rad) must flex the measured wrist angle;
  // the servo and springs leave an error, but the sign and > half the
  // amplitude must come through.
  HandPlant plant(spec_for(ObjectKind::kNone));
  JointTargets q = grasp_pose(0.05);
  plant.settle(nominal_muscle_lengths_mm(q), 1.0);
  const double rest = plant.state().wrist_rad[0];
  q.wrist_pitch_rad = 0.4;
  for (int k = 0; k < 10; ++k) plant.step(nominal_muscle_lengths_mm(q));
  EXPECT_GT(plant.state().wrist_rad[0] - rest, 0.2);
}

}  // namespace
}  // namespace hadynet::plant
