#include "host-sim/plant/motions.h"

namespace hadynet::plant {

std::string_view motion_name(Motion motion) { return motion == Motion::kRandom1 ? "random1" : "random2"; }

std::optional<Motion> parse_motion(std::string_view name) {
  if (name == "random1" || name == "Random-1") return Motion::kRandom1;
  if (name == "random2" || name == "Random-2") return Motion::kRandom2;
  return std::nullopt;
}

JointTargets start_pose() {
  JointTargets q;
  q.index_middle = q.ring_little = 0.05;
  q.thumb_flex = q.thumb_oppose = 0.05;
  return q;
}

MotionGenerator::MotionGenerator(Motion motion, ObjectKind object, std::uint64_t seed)
    : motion_(motion), object_(object), rng_(seed) {
  current_mm_ = nominal_muscle_lengths_mm(start_pose());
  from_mm_ = to_mm_ = current_mm_;
}

void MotionGenerator::plan_segment() {
  from_mm_ = current_mm_;
  segment_pos_ = 0;
  if (motion_ == Motion::kRandom1) {
    JointTargets q;
    q.wrist_pitch_rad = rng_.uniform(-0.6, 0.6);
    q.wrist_yaw_rad = rng_.uniform(-0.3, 0.3);
    q.index_middle = rng_.uniform(0.0, 1.0);
    q.ring_little = rng_.uniform(0.0, 1.0);
    q.thumb_flex = rng_.uniform(0.0, 1.0);
    q.thumb_oppose = rng_.uniform(0.0, 1.0);
    q.stiffness = rng_.uniform(0.0, 1.0);
    to_mm_ = nominal_muscle_lengths_mm(q);
    segment_steps_ = rng_.uniform_int(3, 15);  // 0.6 .. 3.0 s
  } else if (segments_done_ == 0) {
    // Grasp: close the hand around the object (or bend the fingers a
    // moderate amount when there is none) over kGraspSteps (1.6 s).
    JointTargets q;
    q.wrist_pitch_rad = rng_.uniform(-0.2, 0.2);
    q.wrist_yaw_rad = rng_.uniform(-0.1, 0.1);
    const double close = object_ == ObjectKind::kNone ? rng_.uniform(0.4, 0.6) : rng_.uniform(0.85, 0.95);
    q.index_middle = q.ring_little = close;
    q.thumb_flex = rng_.uniform(0.4, 0.7);
    q.thumb_oppose = rng_.uniform(0.4, 0.7);
    q.stiffness = rng_.uniform(0.0, 1.0);
    to_mm_ = grasp_mm_ = nominal_muscle_lengths_mm(q);
    segment_steps_ = kGraspSteps;
  } else {
    // Random changes of the finger muscles #1-#4 around the grasp.
    to_mm_ = current_mm_;
    for (int m : kFingerMuscles) to_mm_[m] = grasp_mm_[m] + rng_.uniform(-4.0, 3.0);
    segment_steps_ = rng_.uniform_int(2, 8);  // 0.4 .. 1.6 s
  }
  ++segments_done_;
}

std::array<double, kMuscles> MotionGenerator::next_target() {
  if (segment_pos_ >= segment_steps_) plan_segment();
  ++segment_pos_;
  const double a = static_cast<double>(segment_pos_) / segment_steps_;
  for (int m = 0; m < kMuscles; ++m) current_mm_[m] = from_mm_[m] + a * (to_mm_[m] - from_mm_[m]);
  return current_mm_;
}

}  // namespace hadynet::plant
