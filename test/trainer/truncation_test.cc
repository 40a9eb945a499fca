// Truncated BPTT. A truncated gradient is not the gradient of L, so it is
// checked against central finite differences of the truncated objective
// L_K(theta) built by the naive reference (reference_truncated_outputs: for
// output k the state at step k-K+1 >= 1 is a constant taken from the forward
// at theta_0). At theta_0 the analytic truncated gradient must equal
// dL_K/dtheta, with the tolerance of finite_difference.h.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <tuple>
#include <vector>

#include "finite_difference.h"
#include "reference_hadynet.h"
#include "test_batches.h"
#include "trainer/hadynet_network.h"

namespace hadynet::trainer::testing {
namespace {

const HadynetDims kDims{3, 2, 3, 2, 5, 3};
constexpr int kWindows = 4;
constexpr int kSteps = 5;
const std::vector<int> kStates{0, 2, 1, 2};

struct Problem {
  HadynetParams<double> params = generic_params(kDims, 21);
  WindowBatch<double> batch = random_batch(kDims, kWindows, kSteps, 22, kStates);
  Matrix<double> y;
  Problem() {
    std::mt19937_64 rng(23);
    y = random_matrix(rng, kDims.y, kSteps * kWindows);
  }
};

HadynetGrads<double> gradient(const Problem& s, BnMode mode, int truncation) {
  HadynetNetwork<double> net;
  Matrix<double> d_y_hat;
  mse_loss(net.forward(s.params, s.batch, mode), s.y, &d_y_hat);
  HadynetGrads<double> grads;
  net.backward(s.params, d_y_hat, grads, truncation);
  return grads;
}

bool bit_identical(const HadynetGrads<double>& a, const HadynetGrads<double>& b) {
  const auto ta = a.params.tensors();
  const auto tb = b.params.tensors();
  for (std::size_t t = 0; t < ta.size(); ++t) {
    if (std::memcmp(ta[t].data, tb[t].data, sizeof(double) * ta[t].size()) != 0) return false;
  }
  return a.u == b.u && a.pb_window == b.pb_window;
}

TEST(Truncation, DepthOfNOrMoreIsFullBptt) {
  const Problem s;
  for (BnMode mode : {BnMode::kTrain, BnMode::kEval}) {
    const HadynetGrads<double> full = gradient(s, mode, kFullBptt);
    EXPECT_TRUE(bit_identical(full, gradient(s, mode, kSteps)));
    EXPECT_TRUE(bit_identical(full, gradient(s, mode, kSteps + 3)));
  }
}

TEST(Truncation, ShorterDepthChangesTheGradient) {
  const Problem s;
  const HadynetGrads<double> full = gradient(s, BnMode::kTrain, kFullBptt);
  for (int k = 1; k < kSteps; ++k) {
    const HadynetGrads<double> cut = gradient(s, BnMode::kTrain, k);
    EXPECT_GT((cut.params.lstm_weight_hh - full.params.lstm_weight_hh).cwiseAbs().maxCoeff(), 1e-6)
        << "K=" << k;
    // The last command reaches only the last output: no path is ever cut.
    EXPECT_TRUE(cut.u.rightCols(kWindows).isApprox(full.u.rightCols(kWindows), 1e-12)) << "K=" << k;
  }
}

TEST(Truncation, DepthBelowOneIsRejected) {
  const Problem s;
  EXPECT_THROW(gradient(s, BnMode::kEval, 0), std::invalid_argument);
}

class TruncatedGradient : public ::testing::TestWithParam<std::tuple<BnMode, int>> {
 protected:
  BnMode mode() const { return std::get<0>(GetParam()); }
  int depth() const { return std::get<1>(GetParam()); }

  // L_K at the current s_.params / s_.batch, with states frozen at theta_0.
  double truncated_loss() const {
    const std::vector<RefWindow> windows = to_reference(s_.batch, s_.params);
    const std::vector<std::vector<Vec>> out =
        reference_truncated_outputs(s_.params, windows, mode(), depth(), frozen_);
    double sum = 0.0;
    for (int b = 0; b < kWindows; ++b) {
      for (int k = 0; k < kSteps; ++k) {
        for (int j = 0; j < kDims.y; ++j) {
          const double e = out[b][k][j] - s_.y(j, k * kWindows + b);
          sum += e * e;
        }
      }
    }
    return sum / static_cast<double>(kWindows * kSteps * kDims.y);
  }

  void SetUp() override {
    frozen_ = reference_forward(s_.params, to_reference(s_.batch, s_.params), mode());
  }

  Problem s_;
  std::vector<RefTrace> frozen_;
};

TEST_P(TruncatedGradient, EqualsFiniteDifferencesOfTheTruncatedObjective) {
  const HadynetGrads<double> grads = gradient(s_, mode(), depth());
  const std::vector<NamedTensor<const double>> g = grads.params.tensors();
  std::vector<NamedTensor<double>> p = s_.params.tensors();
  for (std::size_t t = 0; t < p.size(); ++t) {
    if (!p[t].trainable) continue;
    for (int i = 0; i < p[t].size(); ++i) {
      const double numeric = central_difference(&p[t].data[i], [&] { return truncated_loss(); });
      EXPECT_TRUE(gradient_close(g[t].data[i], numeric)) << p[t].name << "[" << i << "]";
    }
  }
  for (Eigen::Index i = 0; i < s_.batch.u.size(); ++i) {
    const double numeric =
        central_difference(&s_.batch.u.data()[i], [&] { return truncated_loss(); });
    EXPECT_TRUE(gradient_close(grads.u.data()[i], numeric)) << "u[" << i << "]";
  }
}

INSTANTIATE_TEST_SUITE_P(ModesAndDepths, TruncatedGradient,
                         ::testing::Combine(::testing::Values(BnMode::kTrain, BnMode::kEval),
                                            ::testing::Values(1, 2, 3, 5)),
                         [](const auto& param_info) {
                           return std::string(std::get<0>(param_info.param) == BnMode::kTrain
                                                  ? "Train"
                                                  : "Eval") +
                                  "K" + std::to_string(std::get<1>(param_info.param));
                         });

}  // namespace
}  // namespace hadynet::trainer::testing
