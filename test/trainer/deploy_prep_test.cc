// Codegen preparation: batch-norm folding and the measured value ranges.
#include <gtest/gtest.h>

#include <numeric>

#include "synthetic_logs.h"
#include "test_batches.h"
#include "trainer/data_hash.h"
#include "trainer/deploy_prep.h"

namespace hadynet::trainer::testing {
namespace {

// The spring model with generic (non-identity) BN statistics, so folding has
// something to fold.
HadynetModel model_with_generic_bn(const SpringModel& spring) {
  HadynetModel m = spring.model;
  const HadynetParams<double> g = generic_params(m.params.dims, 77);
  m.params.enc_bn_weight = g.enc_bn_weight.cast<float>();
  m.params.enc_bn_bias = g.enc_bn_bias.cast<float>();
  m.params.enc_bn_running_mean = g.enc_bn_running_mean.cast<float>();
  m.params.enc_bn_running_var = g.enc_bn_running_var.cast<float>();
  return m;
}

std::vector<int> all_ids(const WindowDataset& data) {
  std::vector<int> ids(static_cast<std::size_t>(data.size()));
  std::iota(ids.begin(), ids.end(), 0);
  return ids;
}

TEST(FoldBatchNorm, FoldedEncoderEqualsBatchNormInEvalMode) {
  const SpringModel spring = trained_spring_model(5);
  const HadynetModel m = model_with_generic_bn(spring);
  const WindowDataset data(spring.train, {0, 1}, m.layout, m.norm, kSpringTrainSteps);
  const std::vector<int> ids = all_ids(data);
  WindowBatch<float> batch;
  Matrix<float> y;
  data.gather(ids, batch, y);
  HadynetNetwork<float> net;
  net.forward(m.params, batch, BnMode::kEval);
  const Eigen::Index B = batch.windows();
  Matrix<float> enc_in(m.params.dims.x + m.params.dims.pb, B);
  for (Eigen::Index b = 0; b < B; ++b) {
    enc_in.col(b) << batch.x0.col(b),
        m.params.pb.row(batch.state[static_cast<std::size_t>(b)]).transpose();
  }
  const FoldedEncoder folded = fold_batch_norm(m.params);
  const Matrix<float> h0 = ((folded.weight * enc_in).colwise() + folded.bias).cwiseMax(0.0f);
  // Float rounding of two differently ordered computations of O(1) values
  // from ~10-term dot products: a few ulps, far below 1e-5.
  EXPECT_LT((h0 - net.hidden_states().leftCols(B)).cwiseAbs().maxCoeff(), 1e-5f);
}

TEST(MeasureRanges, MatchesAnIndependentComputation) {
  const SpringModel spring = trained_spring_model(5);
  const HadynetModel& m = spring.model;
  const WindowDataset data(spring.train, {0, 1}, m.layout, m.norm, kSpringTrainSteps);
  const std::vector<int> ids = all_ids(data);
  const ValueRanges r = measure_ranges(m, data, ids);

  // Independent: per window, run the LSTM cell by hand from the network's h_k.
  WindowBatch<float> batch;
  Matrix<float> y;
  data.gather(ids, batch, y);
  HadynetNetwork<float> net;
  const Matrix<float> y_hat = net.forward(m.params, batch, BnMode::kEval);
  const Eigen::Index B = batch.windows(), N = kSpringTrainSteps, H = m.params.dims.hidden;
  double gate_max = 0, c_max = 0;
  for (Eigen::Index b = 0; b < B; ++b) {
    const Eigen::VectorXf p = m.params.pb.row(batch.state[static_cast<std::size_t>(b)]).transpose();
    Eigen::VectorXf c = Eigen::VectorXf::Zero(H);
    for (Eigen::Index k = 0; k < N; ++k) {
      Eigen::VectorXf in(m.params.dims.u + m.params.dims.pb);
      in << batch.u.col(k * B + b), p;
      const Eigen::VectorXf pre = m.params.lstm_weight_ih * in + m.params.lstm_bias_ih +
                                  m.params.lstm_bias_hh +
                                  m.params.lstm_weight_hh * net.hidden_states().col(k * B + b);
      gate_max = std::max(gate_max, static_cast<double>(pre.cwiseAbs().maxCoeff()));
      const auto sig = [](const Eigen::VectorXf& v) {
        return (1.0f / (1.0f + (-v.array()).exp())).matrix().eval();
      };
      c = sig(pre.segment(H, H)).cwiseProduct(c) +
          sig(pre.head(H)).cwiseProduct(pre.segment(2 * H, H).array().tanh().matrix());
      c_max = std::max(c_max, static_cast<double>(c.cwiseAbs().maxCoeff()));
    }
  }
  // Same quantities in a different summation order: relative 1e-5.
  EXPECT_NEAR(r.gate_pre, gate_max, 1e-5 * gate_max);
  EXPECT_NEAR(r.c, c_max, 1e-5 * c_max);
  EXPECT_FLOAT_EQ(static_cast<float>(r.y), y_hat.cwiseAbs().maxCoeff());
  EXPECT_FLOAT_EQ(static_cast<float>(r.x), batch.x0.cwiseAbs().maxCoeff());
  EXPECT_FLOAT_EQ(static_cast<float>(r.u), batch.u.cwiseAbs().maxCoeff());
  // |h| = |o tanh(c)| < 1 always; and the encoder output is a ReLU of enc_pre.
  EXPECT_LT(r.h, 1.0 + 1e-6 + r.enc_pre);
  EXPECT_GT(r.enc_weight, 0.0);
  EXPECT_FLOAT_EQ(static_cast<float>(r.dec_weight), m.params.dec_weight.cwiseAbs().maxCoeff());
}

TEST(MeasureLogRanges, EveryWindowOfTheLogsWithTheirStatesPb) {
  const SpringModel spring = trained_spring_model(3);
  const HadynetModel& m = spring.model;
  TempDir dir;
  const std::string soft = dir.write_log("logs/a.csv", spring_log(kSoftStiffness, 40, 21, "soft"));
  const std::string stiff = dir.write_log("logs/b.csv", spring_log(kStiffStiffness, 30, 22, "stiff"));
  const ValueRanges r = measure_log_ranges(m, {(dir.path() / "logs").string()});

  // Independent: the same windows through measure_ranges (stiff is PB row 1).
  const std::vector<LogSequence> seqs = {read_sequence(soft, m.layout), read_sequence(stiff, m.layout)};
  const WindowDataset data(seqs, {0, 1}, m.layout, m.norm, m.train_steps);
  ValueRanges want = measure_ranges(m, data, all_ids(data));
  EXPECT_EQ(r.windows, data.size());
  EXPECT_EQ(r.windows, (40 - 1 - kSpringTrainSteps) + (30 - 1 - kSpringTrainSteps));
  EXPECT_TRUE(contains(r.source, "2 logs (data_hash " + data_hash({soft, stiff}) + ")")) << r.source;
  want.source = r.source;
  EXPECT_EQ(r, want);  // same windows, same order of computation: exact

  // A log of a state the PB table does not have is an error naming the file.
  const std::string other = dir.write_log("other/c.csv", spring_log(2.0, 30, 23, "medium"));
  try {
    measure_log_ranges(m, {other});
    ADD_FAILURE() << "a state outside the PB table was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(contains(e.what(), other + ": state 'medium'")) << e.what();
  }
  // Logs too short for one window.
  const std::string tiny = dir.write_log("tiny/d.csv", spring_log(1.0, 4, 24, "soft"));
  EXPECT_THROW(measure_log_ranges(m, {tiny}), std::runtime_error);
}

}  // namespace
}  // namespace hadynet::trainer::testing
