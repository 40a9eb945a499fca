// End-to-end behaviour of the numerical core in float on the synthetic
// mass-spring data (synthetic_dynamics.h): joint training of weights and PB
// with Adam, PB-only adaptation with frozen weights, determinism.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "test_batches.h"
#include "synthetic_dynamics.h"
#include "trainer/hadynet_network.h"
#include "trainer/optim.h"

namespace hadynet::trainer::testing {
namespace {

// x = (q, v), u = force, y = (q, v); 3 PB rows: two trained states and one
// kept for adaptation to a third, shifted state.
const HadynetDims kDims{2, 1, 2, 2, 16, 3};
constexpr int kWindowSteps = 10;
constexpr int kSequenceSteps = 60;  // 51 windows per state
constexpr std::uint64_t kSeed = 2024;

DynamicsWindows training_data() {
  return make_dynamics_windows({1.0, 4.0}, {0, 1}, kSequenceSteps, kWindowSteps, 100);
}

float full_batch_loss(const HadynetParams<float>& p, const DynamicsWindows& data, BnMode mode) {
  HadynetNetwork<float> net;
  return mse_loss(net.forward(p, data.batch, mode), data.y, nullptr);
}

// `steps` full-batch Adam steps (lr 1e-2) on weights and PB; BN in training
// mode with the running statistics updated after every step.
HadynetParams<float> train(const DynamicsWindows& data, std::uint64_t seed, int steps) {
  HadynetParams<float> p = HadynetParams<float>::initialized(kDims, seed);
  Adam<float>::Options options;
  options.lr = 1e-2;
  Adam<float> adam(options);
  HadynetNetwork<float> net;
  HadynetGrads<float> grads;
  Matrix<float> d_y_hat;
  for (int i = 0; i < steps; ++i) {
    mse_loss(net.forward(p, data.batch, BnMode::kTrain), data.y, &d_y_hat);
    net.backward(p, d_y_hat, grads);
    net.update_bn_running_stats(p);
    adam.step(p, grads.params);
  }
  return p;
}

using testing::bit_identical;  // the HadynetParams overload (test_batches.h)

bool bit_identical(const NamedTensor<const float>& a, const NamedTensor<const float>& b) {
  return a.size() == b.size() && std::memcmp(a.data, b.data, sizeof(float) * a.size()) == 0;
}

class Training : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    data_ = new DynamicsWindows(training_data());
    trained_ = new HadynetParams<float>(train(*data_, kSeed, 200));
  }
  static void TearDownTestSuite() {
    delete trained_;
    delete data_;
  }
  static DynamicsWindows* data_;
  static HadynetParams<float>* trained_;
};

DynamicsWindows* Training::data_ = nullptr;
HadynetParams<float>* Training::trained_ = nullptr;

TEST_F(Training, LossFallsMoreThanFiveFoldIn200AdamSteps) {
  const float before =
      full_batch_loss(HadynetParams<float>::initialized(kDims, kSeed), *data_, BnMode::kTrain);
  const float after = full_batch_loss(*trained_, *data_, BnMode::kTrain);
  const float after_eval = full_batch_loss(*trained_, *data_, BnMode::kEval);
  RecordProperty("loss_before", std::to_string(before));
  RecordProperty("loss_after", std::to_string(after));
  std::printf("loss before %.5f, after 200 steps %.5f (BN eval: %.5f), ratio %.1f\n", before, after,
              after_eval, before / after);
  EXPECT_LT(after * 5.0f, before);
  EXPECT_LT(after_eval * 5.0f, before);  // the running statistics serve too
}

TEST_F(Training, PbOfTheTwoStatesEndUpDifferent) {
  const Vector<float> p0 = trained_->pb.row(0).transpose();
  const Vector<float> p1 = trained_->pb.row(1).transpose();
  std::printf("p0 = (%.4f, %.4f), p1 = (%.4f, %.4f), unused p2 = (%.4f, %.4f)\n", p0(0), p0(1),
              p1(0), p1(1), trained_->pb(2, 0), trained_->pb(2, 1));
  EXPECT_GT((p0 - p1).norm(), 0.1f);
  EXPECT_EQ(trained_->pb.row(2).norm(), 0.0f);  // never in a batch: zero gradient, no Adam move
}

TEST_F(Training, PbOnlyUpdateLowersLossOnAShiftedState) {
  // New data from stiffness 2.5 1/s^2 as state 2, whose PB starts at the
  // trained PB of state 0 (a stale PB).
  const DynamicsWindows shifted =
      make_dynamics_windows({2.5}, {2}, kSequenceSteps, kWindowSteps, 200);
  HadynetParams<float> p = *trained_;
  p.pb.row(2) = p.pb.row(0);
  const HadynetParams<float> frozen = p;

  MomentumSgd<float>::Options options;
  options.lr = 0.1;
  MomentumSgd<float> sgd(options);  // PB group only
  HadynetNetwork<float> net;
  HadynetGrads<float> grads;
  Matrix<float> d_y_hat;
  const float before = full_batch_loss(p, shifted, BnMode::kEval);
  for (int epoch = 0; epoch < 20; ++epoch) {  // full batch, 20 epochs (paper's N_update)
    mse_loss(net.forward(p, shifted.batch, BnMode::kEval), shifted.y, &d_y_hat);
    net.backward(p, d_y_hat, grads);
    sgd.step(p, grads.params);
  }
  const float after = full_batch_loss(p, shifted, BnMode::kEval);
  std::printf("shifted state: loss %.5f -> %.5f (%.0f %% lower), p2 = (%.4f, %.4f)\n", before,
              after, 100.0 * (1.0 - after / before), p.pb(2, 0), p.pb(2, 1));
  EXPECT_LT(after, 0.9f * before);

  // Only row 2 of the PB table moved.
  const auto now = std::as_const(p).tensors();
  const auto was = frozen.tensors();
  for (std::size_t t = 0; t + 1 < now.size(); ++t)
    EXPECT_TRUE(bit_identical(now[t], was[t])) << now[t].name;
  EXPECT_EQ(p.pb.topRows(2), frozen.pb.topRows(2));
  EXPECT_NE(p.pb.row(2), frozen.pb.row(2));
}

TEST(TrainingDeterminism, SameSeedGivesBitIdenticalParameters) {
  const DynamicsWindows data = training_data();
  const HadynetParams<float> a = train(data, 7, 25);
  const HadynetParams<float> b = train(data, 7, 25);
  EXPECT_TRUE(bit_identical(a, b));
  EXPECT_FALSE(bit_identical(a, train(data, 8, 25)));
}

}  // namespace
}  // namespace hadynet::trainer::testing
