// The two data-collection motions of the seed paper, as sequences of target
// muscle lengths (encoder mm), one per 0.2 s step.
//  Random-1: random target joint angles, turned into target muscle lengths by
//            the geometric moment-arm model, reached over random durations.
//  Random-2: grasp, then random changes of the finger muscles #1-#4 only.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

#include "host-sim/plant/hand_spec.h"
#include "host-sim/plant/muscle_model.h"
#include "host-sim/plant/rng.h"

namespace hadynet::plant {

enum class Motion { kRandom1, kRandom2 };
std::string_view motion_name(Motion motion);  // "random1", "random2"
std::optional<Motion> parse_motion(std::string_view name);

// The open-hand pose every experiment starts from.
JointTargets start_pose();

// Random-2 closes the hand around the object over this many 0.2 s steps
// before its random finger changes begin.
inline constexpr int kGraspSteps = 8;

class MotionGenerator {
 public:
  MotionGenerator(Motion motion, ObjectKind object, std::uint64_t seed);
  // Target muscle lengths for the end of the next step.
  std::array<double, kMuscles> next_target();

 private:
  void plan_segment();

  Motion motion_;
  ObjectKind object_;
  Rng rng_;
  std::array<double, kMuscles> current_mm_{};
  std::array<double, kMuscles> from_mm_{}, to_mm_{};
  std::array<double, kMuscles> grasp_mm_{};
  int segment_steps_ = 0;
  int segment_pos_ = 0;
  int segments_done_ = 0;
};

}  // namespace hadynet::plant
