// fine_tune's learning rate of the input weights a fix adds at zero
// (FineTuneOptions::added_u_columns, added_input_lr_scale): one Adam step
// moves those columns added_input_lr_scale times as far as at lr and every
// other weight exactly as at lr. The two damped mass-springs of the trainer
// tests and their small trained model, with friction's derived inputs of u0.
#include <gtest/gtest.h>

#include <stdexcept>

#include "test/trainer/synthetic_logs.h"
#include "test/trainer/test_batches.h"
#include "trainer/residual/augment.h"
#include "trainer/residual/fine_tune.h"

namespace hadynet::test {
namespace {

using namespace trainer::residual;
namespace tt = trainer::testing;

struct Augmented {
  trainer::HadynetModel model;
  std::vector<trainer::LogSequence> seqs;
  std::vector<int> states;
};

// The spring model with sign_u0 and hyst_u0 appended to u (u columns 2, 3),
// and two 200-row logs of its "soft" state in that layout.
Augmented with_friction_inputs() {
  static const trainer::HadynetModel spring = tt::trained_spring_model(20).model;
  Augmentation a;
  a.kind = EffectKind::kFriction;
  a.effect = "friction";
  a.change = DerivedCommandInputs{{}, {"sign_u0", "hyst_u0"}};
  Augmented out;
  const trainer::FeatureLayout layout = augmented_layout(spring.layout, a);
  for (std::uint64_t seed : {201u, 202u})
    out.seqs.push_back(trainer::log_sequence(tt::spring_log(tt::kSoftStiffness, 200, seed, "soft"), "soft.csv", layout));
  out.model = augmented_model(spring, a, out.seqs);
  const Eigen::VectorXf pb = spring.params.pb.row(spring.state_index("soft")).transpose();
  out.states = ensure_states(out.model, out.seqs, {pb, pb});
  return out;
}

// One step: every window in one batch, one epoch.
FineTuneOptions one_step(double scale) { return {1, 1 << 20, 1e-3, 1, {2, 3}, scale}; }

TEST(ResidualFineTune, AddedInputColumnsStartAtZero) {
  const Augmented a = with_friction_inputs();
  ASSERT_EQ(a.model.layout.u_names.size(), 4u);
  EXPECT_TRUE(a.model.params.lstm_weight_ih.col(2).isZero(0));
  EXPECT_TRUE(a.model.params.lstm_weight_ih.col(3).isZero(0));
}

TEST(ResidualFineTune, TheAddedColumnsMoveScaleTimesAsFarAndNothingElseChanges) {
  Augmented plain = with_friction_inputs(), scaled = with_friction_inputs();
  long windows = 0;
  fine_tune(plain.model, plain.seqs, plain.states, one_step(1.0), &windows);
  fine_tune(scaled.model, scaled.seqs, scaled.states, one_step(3.0), &windows);
  auto& p = plain.model.params.lstm_weight_ih;
  auto& s = scaled.model.params.lstm_weight_ih;
  for (const int c : {2, 3}) {
    // Both started at zero: the step is Adam's at lr, exactly 3 times (a
    // float times 3 is exact up to one rounding, done the same way in both).
    ASSERT_GT(p.col(c).cwiseAbs().maxCoeff(), 0.0f) << "u column " << c << " had no gradient";
    const Eigen::VectorXf expected = 3.0f * p.col(c);
    EXPECT_EQ(s.col(c), expected) << "u column " << c;
  }
  // Every other weight, the PB table and the moments' effect on them: bit for bit.
  s.col(2) = p.col(2);
  s.col(3) = p.col(3);
  EXPECT_TRUE(tt::bit_identical(plain.model.params, scaled.model.params));
}

TEST(ResidualFineTune, AnAddedColumnOutsideTheInputsIsRejected) {
  Augmented a = with_friction_inputs();
  FineTuneOptions o = one_step(3.0);
  o.added_u_columns = {4};
  long windows = 0;
  EXPECT_THROW(fine_tune(a.model, a.seqs, a.states, o, &windows), std::invalid_argument);
}

}  // namespace
}  // namespace hadynet::test
