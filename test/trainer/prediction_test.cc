// Simulation and N-step prediction errors in physical units
// (trainer/prediction.h), against the network run directly on the
// standardised window.
#include "trainer/prediction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "synthetic_logs.h"
#include "test_batches.h"
#include "trainer/hadynet_network.h"
#include "trainer/training.h"
#include "trainer/window_dataset.h"

namespace hadynet::trainer::testing {
namespace {

struct PredictionData {
  LogSequence seq = spring_sequence(3.0, 30, 51, "mid");
  FeatureLayout layout = spring_layout();
  HadynetModel model = [this] {
    HadynetModel m = new_model(layout, fit_normalization({seq}, layout), {{"a", ""}, {"b", ""}},
                               2, 8, 5, 13);
    m.params = generic_params(m.params.dims, 14).cast<float>();  // BN stats and PB not trivial
    return m;
  }();
  Eigen::VectorXf pb = Eigen::Vector2f(0.3f, -0.6f);
};

TEST(Simulate, IsTheForwardOfTheStandardisedWindowDestandardised) {
  const PredictionData s;
  const int t = 4, N = 6;
  const Eigen::VectorXd x0 = initial_state(s.layout, s.seq, t);
  const Eigen::MatrixXd u = s.seq.u.middleCols(t, N);
  const Eigen::MatrixXd sim = simulate(s.model, x0, u, s.pb);
  ASSERT_EQ(sim.rows(), 4);
  ASSERT_EQ(sim.cols(), N);

  // Reference: the same window gathered by WindowDataset, explicit PB, BN eval.
  const WindowDataset data({s.seq}, {0}, s.layout, s.model.norm, N);
  const std::vector<int> id = {t - 1};  // window ids start at i = 1
  ASSERT_EQ(data.window(id[0]).start, t);
  WindowBatch<float> batch;
  Matrix<float> y;
  data.gather(id, batch, y);
  batch.pb = s.pb;
  HadynetNetwork<float> net;
  const Matrix<float> y_hat = net.forward(s.model.params, batch, BnMode::kEval);
  // Same float inputs, same network: the float outputs are bit-identical,
  // and so is the one double de-standardisation applied to them.
  for (int k = 0; k < N; ++k) {
    const Eigen::VectorXd want = s.model.norm.y.physical(y_hat.col(k).cast<double>());
    EXPECT_EQ(Eigen::VectorXd(sim.col(k)), want) << "step " << k;
  }
  // The PB matters (the comparison above is not PB-blind).
  EXPECT_NE(simulate(s.model, x0, u, Eigen::Vector2f(-0.3f, 0.6f)), sim);
}

TEST(Simulate, RejectsWrongSizes) {
  const PredictionData s;
  const Eigen::VectorXd x0 = initial_state(s.layout, s.seq, 1);
  const Eigen::MatrixXd u = s.seq.u.middleCols(1, 3);
  EXPECT_THROW(simulate(s.model, x0.head(5), u, s.pb), std::invalid_argument);
  EXPECT_THROW(simulate(s.model, x0, u.topRows(1), s.pb), std::invalid_argument);
  EXPECT_THROW(simulate(s.model, x0, Eigen::MatrixXd(2, 0), s.pb), std::invalid_argument);
  EXPECT_THROW(simulate(s.model, x0, u, Eigen::VectorXf::Zero(3)), std::invalid_argument);
}

TEST(PredictionErrors, ColumnJIsTheStepsAheadErrorAtTEqualsJPlusOnePlusSteps) {
  const PredictionData s;
  const int steps = 3;
  const Eigen::MatrixXd e = prediction_errors(s.model, s.seq, s.pb, steps);
  ASSERT_EQ(e.rows(), 4);
  ASSERT_EQ(e.cols(), s.seq.steps() - 1 - steps);
  for (const int j : {0, 7, static_cast<int>(e.cols()) - 1}) {
    const int t = j + 1 + steps;
    const Eigen::MatrixXd sim = simulate(s.model, initial_state(s.layout, s.seq, t - steps),
                                         s.seq.u.middleCols(t - steps, steps), s.pb);
    const Eigen::VectorXd want =
        s.model.norm.y.standardize(sim.col(steps - 1)) - s.model.norm.y.standardize(s.seq.y.col(t));
    // prediction_errors subtracts in float (targets rounded to float) and
    // runs all windows in one batch; simulate runs one window and works in
    // double: differences of a few float ulps of O(1) values, so 1e-5.
    EXPECT_LT((Eigen::VectorXd(e.col(j)) - want).cwiseAbs().maxCoeff(), 1e-5) << "column " << j;
    EXPECT_GT(want.norm(), 1e-2);  // errors of an untrained net: not trivially 0
  }
}

TEST(PredictionErrors, ShortLogsGiveNoColumnsAndStepsMustBePositive) {
  const PredictionData s;
  const LogSequence short_seq = spring_sequence(3.0, 4, 52, "short");
  EXPECT_EQ(prediction_errors(s.model, short_seq, s.pb, 3).cols(), 0);  // T - 1 - steps = 0
  EXPECT_EQ(prediction_errors(s.model, short_seq, s.pb, 2).cols(), 1);
  EXPECT_THROW(prediction_errors(s.model, s.seq, s.pb, 0), std::invalid_argument);
}

}  // namespace
}  // namespace hadynet::trainer::testing
