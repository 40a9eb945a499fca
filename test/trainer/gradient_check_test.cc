// Full-BPTT gradients of the batched network against central finite
// differences of its own loss, in double, for every element of every
// parameter tensor, of the commands u and of an explicit per-window PB, in
// BN training and eval mode. Tolerance: finite_difference.h.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "finite_difference.h"
#include "test_batches.h"
#include "trainer/hadynet_network.h"

namespace hadynet::trainer::testing {
namespace {

// Small sizes, all different, so that a transposed or swapped index shows.
const HadynetDims kDims{3, 2, 3, 2, 5, 4};
constexpr int kWindows = 4;
constexpr int kSteps = 5;
// State 0 twice (rows are sums over windows), state 3 never (zero gradient).
const std::vector<int> kStates{0, 2, 0, 1};

class GradientCheck : public ::testing::TestWithParam<BnMode> {
 protected:
  GradientCheck()
      : params_(generic_params(kDims, 11)),
        batch_(random_batch(kDims, kWindows, kSteps, 12, kStates)) {
    std::mt19937_64 rng(13);
    y_ = random_matrix(rng, kDims.y, kSteps * kWindows);
  }

  double loss() {
    HadynetNetwork<double> net;
    return mse_loss(net.forward(params_, batch_, GetParam()), y_, nullptr);
  }

  HadynetGrads<double> analytic() {
    HadynetNetwork<double> net;
    Matrix<double> d_y_hat;
    mse_loss(net.forward(params_, batch_, GetParam()), y_, &d_y_hat);
    HadynetGrads<double> grads;
    net.backward(params_, d_y_hat, grads);
    return grads;
  }

  HadynetParams<double> params_;
  WindowBatch<double> batch_;
  Matrix<double> y_;
};

TEST_P(GradientCheck, EveryParameterMatchesFiniteDifferences) {
  const HadynetGrads<double> grads = analytic();
  const std::vector<NamedTensor<const double>> g = grads.params.tensors();
  std::vector<NamedTensor<double>> p = params_.tensors();
  for (std::size_t t = 0; t < p.size(); ++t) {
    if (!p[t].trainable) {
      for (int i = 0; i < g[t].size(); ++i) EXPECT_EQ(g[t].data[i], 0.0) << g[t].name;
      continue;
    }
    double largest = 0.0;
    for (int i = 0; i < p[t].size(); ++i) {
      const double numeric = central_difference(&p[t].data[i], [&] { return loss(); });
      EXPECT_TRUE(gradient_close(g[t].data[i], numeric)) << p[t].name << "[" << i << "]";
      largest = std::max(largest, std::abs(g[t].data[i]));
    }
    // Not vacuous: every group carries gradient (but enc.bias under batch statistics).
    const bool zero_by_construction = p[t].name == "enc.bias" && GetParam() == BnMode::kTrain;
    if (!zero_by_construction) {
      EXPECT_GT(largest, 1e-4) << p[t].name;
    }
  }
}

TEST_P(GradientCheck, UnusedPbRowHasZeroGradient) {
  const HadynetGrads<double> grads = analytic();
  for (int j = 0; j < kDims.pb; ++j) EXPECT_EQ(grads.params.pb(3, j), 0.0);
}

TEST_P(GradientCheck, PbRowsAreSumsOfWindowGradients) {
  const HadynetGrads<double> grads = analytic();
  for (int j = 0; j < kDims.pb; ++j) {
    EXPECT_DOUBLE_EQ(grads.params.pb(0, j), grads.pb_window(j, 0) + grads.pb_window(j, 2));
    EXPECT_DOUBLE_EQ(grads.params.pb(2, j), grads.pb_window(j, 1));
    EXPECT_DOUBLE_EQ(grads.params.pb(1, j), grads.pb_window(j, 3));
  }
}

TEST_P(GradientCheck, ReusedGradsEqualFreshOnes) {
  HadynetNetwork<double> net;
  HadynetGrads<double> reused;
  Matrix<double> d_y_hat;
  mse_loss(net.forward(params_, batch_, GetParam()), y_, &d_y_hat);
  net.backward(params_, d_y_hat, reused);
  batch_.state = {3, 3, 1, 3};
  mse_loss(net.forward(params_, batch_, GetParam()), y_, &d_y_hat);
  net.backward(params_, d_y_hat, reused);
  const HadynetGrads<double> fresh = analytic();
  const auto a = reused.params.tensors();
  const auto b = fresh.params.tensors();
  for (std::size_t t = 0; t < a.size(); ++t) {
    for (int i = 0; i < a[t].size(); ++i) EXPECT_EQ(a[t].data[i], b[t].data[i]) << a[t].name;
  }
  EXPECT_EQ(reused.u, fresh.u);
  EXPECT_EQ(reused.pb_window, fresh.pb_window);
}

TEST_P(GradientCheck, CommandsMatchFiniteDifferences) {
  const HadynetGrads<double> grads = analytic();
  ASSERT_EQ(grads.u.rows(), batch_.u.rows());
  ASSERT_EQ(grads.u.cols(), batch_.u.cols());
  for (Eigen::Index i = 0; i < batch_.u.size(); ++i) {
    const double numeric = central_difference(&batch_.u.data()[i], [&] { return loss(); });
    EXPECT_TRUE(gradient_close(grads.u.data()[i], numeric)) << "u[" << i << "]";
  }
  EXPECT_GT(grads.u.cwiseAbs().maxCoeff(), 1e-4);
}

TEST_P(GradientCheck, ExplicitPbMatchesFiniteDifferences) {
  std::mt19937_64 rng(14);
  batch_.pb = random_matrix(rng, kDims.pb, kWindows, 0.5);
  const HadynetGrads<double> grads = analytic();
  for (Eigen::Index i = 0; i < batch_.pb.size(); ++i) {
    const double numeric = central_difference(&batch_.pb.data()[i], [&] { return loss(); });
    EXPECT_TRUE(gradient_close(grads.pb_window.data()[i], numeric)) << "pb_window[" << i << "]";
  }
  EXPECT_GT(grads.pb_window.cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_EQ(grads.params.pb.cwiseAbs().maxCoeff(), 0.0);  // the table was not used
}

INSTANTIATE_TEST_SUITE_P(BnModes, GradientCheck, ::testing::Values(BnMode::kTrain, BnMode::kEval),
                         [](const auto& param_info) {
                           return std::string(param_info.param == BnMode::kTrain ? "Train"
                                                                                 : "Eval");
                         });

}  // namespace
}  // namespace hadynet::trainer::testing
