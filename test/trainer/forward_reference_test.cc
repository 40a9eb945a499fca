// The batched forward pass against the naive per-window reference
// (reference_hadynet.cc), the BN running-statistics update, the loss and the
// shape checks.
//
// Tolerances (absolute, on outputs of magnitude <= ~5):
//   double batched vs double reference: 1e-12 (only the summation order differs)
//   float batched vs double reference:  2e-5 (float eps 6e-8 times the depth of
//     the computation: 45- and 136-term sums, 10 recurrent steps, BN scaling)
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "reference_hadynet.h"
#include "test_batches.h"
#include "trainer/hadynet_network.h"

namespace hadynet::trainer::testing {
namespace {

constexpr double kDoubleTol = 1e-12;
constexpr double kFloatTol = 2e-5;

const HadynetDims kSmall{3, 2, 3, 2, 5, 4};
const HadynetDims kPaper{37, 8, 27, 8, 128, 6};

// max |batched - reference| over outputs and hidden states.
template <class S>
double max_deviation(const HadynetDims& dims, int B, int N, BnMode mode) {
  const HadynetParams<double> params = generic_params(dims, 31);
  const WindowBatch<double> batch = random_batch(dims, B, N, 32, {0, 1, 2, 3, 1});
  const std::vector<RefTrace> ref = reference_forward(params, to_reference(batch, params), mode);

  const HadynetParams<S> p = params.cast<S>();
  WindowBatch<S> b;
  b.x0 = batch.x0.cast<S>();
  b.u = batch.u.cast<S>();
  b.state = batch.state;
  HadynetNetwork<S> net;
  const Matrix<S>& y_hat = net.forward(p, b, mode);
  const Matrix<S>& h = net.hidden_states();
  double worst = 0.0;
  for (int w = 0; w < B; ++w) {
    for (int k = 0; k < N; ++k) {
      for (int j = 0; j < dims.y; ++j) {
        worst =
            std::max(worst, std::abs(static_cast<double>(y_hat(j, k * B + w)) - ref[w].y[k][j]));
      }
    }
    for (int k = 0; k <= N; ++k) {
      for (int j = 0; j < dims.hidden; ++j) {
        worst = std::max(worst, std::abs(static_cast<double>(h(j, k * B + w)) - ref[w].h[k][j]));
      }
    }
  }
  return worst;
}

TEST(ForwardReference, DoubleMatchesReference) {
  for (BnMode mode : {BnMode::kTrain, BnMode::kEval}) {
    EXPECT_LE(max_deviation<double>(kSmall, 5, 4, mode), kDoubleTol);
    EXPECT_LE(max_deviation<double>(kPaper, 12, 10, mode), kDoubleTol);
  }
}

TEST(ForwardReference, FloatMatchesReference) {
  for (BnMode mode : {BnMode::kTrain, BnMode::kEval}) {
    EXPECT_LE(max_deviation<float>(kSmall, 5, 4, mode), kFloatTol);
    EXPECT_LE(max_deviation<float>(kPaper, 12, 10, mode), kFloatTol);
  }
}

TEST(ForwardReference, ExplicitPbEqualsTableRows) {
  const HadynetParams<double> params = generic_params(kSmall, 33);
  WindowBatch<double> batch = random_batch(kSmall, 4, 3, 34, {2, 0, 3, 2});
  HadynetNetwork<double> net;
  const Matrix<double> from_table = net.forward(params, batch, BnMode::kTrain);
  batch.pb.resize(kSmall.pb, 4);
  for (int b = 0; b < 4; ++b) batch.pb.col(b) = params.pb.row(batch.state[b]).transpose();
  batch.state.clear();
  EXPECT_EQ(net.forward(params, batch, BnMode::kTrain), from_table);
}

TEST(BatchNorm, RunningStatisticsFollowPyTorch) {
  const HadynetParams<double> params = generic_params(kSmall, 35);
  const WindowBatch<double> batch = random_batch(kSmall, 6, 2, 36, {0, 1});
  HadynetParams<double> updated = params;
  HadynetNetwork<double> net;
  net.forward(params, batch, BnMode::kTrain);
  net.update_bn_running_stats(updated);

  // Encoder pre-activations by loops, then PyTorch's update with momentum 0.1.
  const std::vector<RefWindow> w = to_reference(batch, params);
  const int B = 6;
  for (int i = 0; i < kSmall.hidden; ++i) {
    std::vector<double> a(B);
    for (int b = 0; b < B; ++b) {
      a[b] = params.enc_bias(i);
      for (int j = 0; j < kSmall.x; ++j) a[b] += params.enc_weight(i, j) * w[b].x0[j];
      for (int j = 0; j < kSmall.pb; ++j) a[b] += params.enc_weight(i, kSmall.x + j) * w[b].p[j];
    }
    double mean = 0.0;
    for (double v : a) mean += v / B;
    double unbiased = 0.0;
    for (double v : a) unbiased += (v - mean) * (v - mean) / (B - 1);
    EXPECT_NEAR(updated.enc_bn_running_mean(i), 0.9 * params.enc_bn_running_mean(i) + 0.1 * mean,
                1e-14);
    EXPECT_NEAR(updated.enc_bn_running_var(i), 0.9 * params.enc_bn_running_var(i) + 0.1 * unbiased,
                1e-14);
  }
  // Nothing else changes.
  EXPECT_EQ(updated.enc_weight, params.enc_weight);
  EXPECT_EQ(updated.lstm_weight_hh, params.lstm_weight_hh);
  EXPECT_EQ(updated.pb, params.pb);
}

TEST(BatchNorm, RunningUpdateNeedsTrainingForward) {
  HadynetParams<double> params = generic_params(kSmall, 37);
  HadynetNetwork<double> net;
  EXPECT_THROW(net.update_bn_running_stats(params), std::logic_error);
  net.forward(params, random_batch(kSmall, 3, 2, 38, {0}), BnMode::kEval);
  EXPECT_THROW(net.update_bn_running_stats(params), std::logic_error);
}

TEST(MseLoss, MeanOverStepsChannelsAndWindowsWithDerivative) {
  Matrix<double> y_hat(2, 3);
  y_hat << 1, 2, 3, 4, 5, 6;
  Matrix<double> y = Matrix<double>::Zero(2, 3);
  y(1, 2) = 8;  // error -2 there
  Matrix<double> d;
  // squared errors: 1 4 9 16 25 4 -> sum 59 over 6 values
  EXPECT_DOUBLE_EQ(mse_loss(y_hat, y, &d), 59.0 / 6.0);
  EXPECT_DOUBLE_EQ(d(0, 0), 2.0 * 1.0 / 6.0);
  EXPECT_DOUBLE_EQ(d(1, 2), 2.0 * -2.0 / 6.0);
  EXPECT_THROW(mse_loss(y_hat, Matrix<double>(3, 2), nullptr), std::invalid_argument);
}

TEST(ForwardShapes, BadInputsAreRejected) {
  const HadynetParams<double> params = generic_params(kSmall, 39);
  HadynetNetwork<double> net;
  WindowBatch<double> good = random_batch(kSmall, 3, 2, 40, {0, 1, 3});
  EXPECT_NO_THROW(net.forward(params, good, BnMode::kTrain));

  WindowBatch<double> bad = good;
  bad.x0.conservativeResize(kSmall.x + 1, Eigen::NoChange);
  EXPECT_THROW(net.forward(params, bad, BnMode::kEval), std::invalid_argument);
  bad = good;
  bad.u.conservativeResize(Eigen::NoChange, 7);  // not a multiple of B
  EXPECT_THROW(net.forward(params, bad, BnMode::kEval), std::invalid_argument);
  bad = good;
  bad.state[1] = kSmall.states;
  EXPECT_THROW(net.forward(params, bad, BnMode::kEval), std::invalid_argument);
  bad = good;
  bad.state.pop_back();
  EXPECT_THROW(net.forward(params, bad, BnMode::kEval), std::invalid_argument);
  bad = random_batch(kSmall, 1, 2, 41, {0});
  EXPECT_THROW(net.forward(params, bad, BnMode::kTrain), std::invalid_argument);  // BN needs B >= 2
  EXPECT_NO_THROW(net.forward(params, bad, BnMode::kEval));

  HadynetParams<double> wrong = params;
  wrong.lstm_weight_hh.resize(4 * kSmall.hidden, kSmall.hidden + 1);
  EXPECT_THROW(net.forward(wrong, good, BnMode::kEval), std::invalid_argument);
}

}  // namespace
}  // namespace hadynet::trainer::testing
