// The q15 grasp stabiliser in closed loop with the MuJoCo hand (host-sim):
// a grasped cylinder of a state the model never trained on (init 3) is
// struck every second, pushed towards the wrist with a force ramping to 8 N
// (plant::default_strike). Without control the grasp works loose and
// E = h_loss,1 grows; with the stabiliser it must stay lower. Bounds: rows
// of docs/tolerances.md.
#include <gtest/gtest.h>

#include <cstdio>

#include "host-sim/closed_loop/closed_loop.h"
#include "test/firmware/tolerances.h"

namespace hadynet {
namespace {

hostsim::ClosedLoopRun run(bool control, bool disturbed, int input_delay = 0) {
  hostsim::ClosedLoopOptions o;
  o.effects.command_delay_steps = input_delay;
  o.object = plant::ObjectKind::kCylinder;
  o.init_id = 3;
  o.pb_state = "Cylinder/i0/w0";  // the nearest trained state's PB (recognition's answer)
  o.steps = 100;
  o.control = control;
  o.numeric = firmware::Numeric::kQ15;
  if (!disturbed) o.disturbance = plant::Disturbance{};
  return hostsim::run_closed_loop(o);
}

TEST(GraspStabilizerClosedLoop, LowersTheGraspErrorUnderStrikes) {
  const auto without = run(false, true);
  const auto with = run(true, true);
  // Mean E over the second half (steps 51..100), once the strikes are strong.
  const double e_without = without.mean_error(51, 101);
  const double e_with = with.mean_error(51, 101);
  std::printf("strikes: mean E over steps 51..100: %.2f N^2 without control, %.2f with the q15 stabiliser "
              "(ratio %.2f); steps 1..20: %.2f / %.2f\n",
              e_without, e_with, e_with / e_without, without.mean_error(1, 21), with.mean_error(1, 21));
  EXPECT_GT(e_without, 5 * without.mean_error(1, 21)) << "the disturbance no longer loosens the grasp";
  EXPECT_LE(e_with / e_without, test::tolerance("control.e_ratio_max"));
}

// The servos act on each command 2 steps late (plant effect input-delay=2,
// which the build's model lacks): the stabiliser must still hold the grasp
// within the same bound.
TEST(GraspStabilizerClosedLoop, LowersTheGraspErrorUnderStrikesWithACommandDeadTime) {
  const auto without = run(false, true, 2);
  const auto with = run(true, true, 2);
  const auto with_no_delay = run(true, true, 0);
  const double e_without = without.mean_error(51, 101);
  const double e_with = with.mean_error(51, 101);
  std::printf("strikes, 2-step command dead time: mean E over steps 51..100: %.2f N^2 without control, %.2f with "
              "the q15 stabiliser (ratio %.2f; %.2f on the plant without dead time)\n",
              e_without, e_with, e_with / e_without, with_no_delay.mean_error(51, 101));
  EXPECT_NE(e_with, with_no_delay.mean_error(51, 101)) << "the dead time did not reach the plant";
  EXPECT_LE(e_with / e_without, test::tolerance("control.e_ratio_max"));
}

TEST(GraspStabilizerClosedLoop, KeepsAnUndisturbedGraspAsItIs) {
  const auto without = run(false, false);
  const auto with = run(true, false);
  const double e_without = without.mean_error(1, 101);
  const double e_with = with.mean_error(1, 101);
  std::printf("no disturbance: mean E %.2f N^2 without control, %.2f with\n", e_without, e_with);
  EXPECT_LE(e_with, test::tolerance("control.undisturbed_ratio_max") * e_without);
}

}  // namespace
}  // namespace hadynet
