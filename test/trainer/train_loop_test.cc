// The training loop over log windows (trainer/training.h): new_model, the
// per-epoch window order, evaluate_loss, loss falling, determinism and the
// constant-PB ablation. Tolerances are stated per test; determinism and
// the constant PB are checked bit for bit.
#include "test_batches.h"
#include "trainer/training.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <set>
#include <stdexcept>
#include <vector>

#include "synthetic_logs.h"

namespace hadynet::trainer::testing {
namespace {

struct LoopData {
  FeatureLayout layout = spring_layout();
  std::vector<LogSequence> seqs = {spring_sequence(kSoftStiffness, 60, 41, "soft"),
                                   spring_sequence(kStiffStiffness, 60, 42, "stiff")};
  Normalization norm = fit_normalization(seqs, layout);
  WindowDataset data{seqs, {0, 1}, layout, norm, 5};
  WindowDataset::Split split = data.split_tail(0.2);
  HadynetModel fresh = new_model(layout, norm, {{"soft", "a"}, {"stiff", "b"}}, 2, 12, 5, 7);

  TrainOptions options(int epochs, bool variable_pb = true) const {
    TrainOptions o;
    o.epochs = epochs;
    o.batch = 20;
    o.lr = 1e-2;
    o.seed = 3;
    o.variable_pb = variable_pb;
    return o;
  }
  HadynetModel trained(const TrainOptions& o, TrainingState& state) const {
    HadynetModel m = fresh;
    train(m, state, data, split.train, split.held_out, o, [](const EpochStats&) {});
    return m;
  }
};

std::vector<int> all_ids(const WindowDataset& data) {
  std::vector<int> ids(static_cast<std::size_t>(data.size()));
  std::iota(ids.begin(), ids.end(), 0);
  return ids;
}

TEST(NewModel, SizesFromTheLayoutAndAZeroPbTable) {
  const LoopData s;
  const HadynetModel& m = s.fresh;
  EXPECT_EQ(m.params.dims, (HadynetDims{6, 2, 4, 2, 12, 2}));
  EXPECT_EQ(m.params.pb, RowMatrix<float>::Zero(2, 2));
  EXPECT_EQ(m.train_steps, 5);
  EXPECT_EQ(m.states[1].name, "stiff");
  EXPECT_EQ(m.states[1].object, "b");
  EXPECT_EQ(m.bn_batches_tracked, 0);
  EXPECT_FALSE(m.detection.has_value());
  // PyTorch initialisation from the seed.
  EXPECT_TRUE(bit_identical(m.params, HadynetParams<float>::initialized(m.params.dims, 7)));
  EXPECT_THROW(new_model(s.layout, s.norm, {{"a", ""}}, 0, 12, 5, 7), std::invalid_argument);
}

TEST(EpochOrder, IsAPermutationThatDependsOnSeedAndEpochOnly) {
  std::vector<int> ids;
  for (int i = 0; i < 50; ++i) ids.push_back(3 * i + 100);  // not 0..n-1
  const std::vector<int> e1 = epoch_order(ids, 9, 1);
  std::vector<int> sorted = e1;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, ids);
  EXPECT_NE(e1, ids);                     // shuffled (chance of identity: 1/50!)
  EXPECT_EQ(epoch_order(ids, 9, 1), e1);  // a function of (seed, epoch)
  EXPECT_NE(epoch_order(ids, 9, 2), e1);
  EXPECT_NE(epoch_order(ids, 10, 1), e1);
  std::set<std::vector<int>> orders;  // every epoch gets its own order
  for (int epoch = 1; epoch <= 20; ++epoch) orders.insert(epoch_order(ids, 9, epoch));
  EXPECT_EQ(orders.size(), 20u);
  EXPECT_TRUE(epoch_order(std::vector<int>{}, 9, 1).empty());
  EXPECT_EQ(epoch_order(std::vector<int>{4}, 9, 1), std::vector<int>{4});
}

// The fresh model with distinct PBs, and its predictions and targets over
// every window of `s` in one batch, BN eval (y_dim x (steps * windows)): the
// reference for evaluate_loss and evaluate_channel_loss, which chunk.
struct EvalReference {
  HadynetModel model;
  std::vector<int> ids;
  Matrix<float> y_hat, y;
  explicit EvalReference(const LoopData& s) : model(s.fresh), ids(all_ids(s.data)) {
    model.params.pb << 0.5f, -0.25f, -0.75f, 1.0f;
    WindowBatch<float> batch;
    s.data.gather(ids, batch, y);
    HadynetNetwork<float> net;
    y_hat = net.forward(model.params, batch, BnMode::kEval);
  }
};

TEST(EvaluateLoss, IsTheEvalModeMseOfTheWindowsWithTheirOwnOrAGivenPb) {
  const LoopData s;
  const EvalReference r(s);
  const HadynetModel& m = r.model;
  const std::vector<int>& ids = r.ids;
  const double ref = static_cast<double>(mse_loss(r.y_hat, r.y));
  // Float sums over ~1000 squared errors, chunked or not: 1e-5 relative
  // covers the rounding; a wrong PB or mode changes the loss by far more.
  EXPECT_NEAR(evaluate_loss(m, s.data, ids), ref, 1e-5 * ref);
  EXPECT_NEAR(evaluate_loss(m, s.data, ids, {}, 7), ref, 1e-5 * ref);

  // An explicit PB for all windows: equal to the table loss when every
  // window belongs to that PB's state.
  std::vector<int> stiff;
  for (int id : ids)
    if (s.data.window(id).sequence == 1) stiff.push_back(id);
  const Eigen::VectorXf p1 = m.params.pb.row(1).transpose();
  const double with_table = evaluate_loss(m, s.data, stiff);
  EXPECT_NEAR(evaluate_loss(m, s.data, stiff, p1), with_table, 1e-5 * with_table);
  const Eigen::VectorXf p0 = m.params.pb.row(0).transpose();
  EXPECT_GT(std::abs(evaluate_loss(m, s.data, stiff, p0) - with_table), 1e-3 * with_table);

  EXPECT_TRUE(std::isnan(evaluate_loss(m, s.data, std::vector<int>{})));
}

TEST(EvaluateLoss, PerChannelLossesAreTheColumnsOfTheMseAndAverageToIt) {
  const LoopData s;
  const EvalReference r(s);
  const HadynetModel& m = r.model;
  const std::vector<int>& ids = r.ids;
  const Matrix<float> err = r.y_hat - r.y;
  const Eigen::VectorXd per_channel = evaluate_channel_loss(m, s.data, ids, {}, 7);
  ASSERT_EQ(per_channel.size(), s.data.y_dim());
  // The same float rounding bound as above (sums over ~1000 squared errors).
  for (int c = 0; c < s.data.y_dim(); ++c) {
    const double ref = static_cast<double>(err.row(c).squaredNorm()) / static_cast<double>(err.cols());
    EXPECT_NEAR(per_channel(c), ref, 1e-5 * ref) << "channel " << c;
  }
  const double mean = evaluate_loss(m, s.data, ids);
  EXPECT_NEAR(per_channel.mean(), mean, 1e-5 * mean);
  EXPECT_TRUE(evaluate_channel_loss(m, s.data, std::vector<int>{}).array().isNaN().all());
}

TEST(TrainLoop, LossFallsOnTheSyntheticStates) {
  const LoopData s;
  TrainingState state;
  const double held_before = evaluate_loss(s.fresh, s.data, s.split.held_out);
  const HadynetModel m = s.trained(s.options(30), state);
  ASSERT_EQ(state.history.size(), 30u);
  ASSERT_EQ(state.epochs_done, 30);
  const EpochStats& first = state.history.front();
  const EpochStats& last = state.history.back();
  std::printf("train loss %.4f -> %.4f, held-out %.4f -> %.4f\n", first.train_loss,
              last.train_loss, held_before, last.held_out_loss);
  for (std::size_t e = 0; e < state.history.size(); ++e) {
    EXPECT_EQ(state.history[e].epoch, static_cast<int>(e) + 1);
    EXPECT_TRUE(std::isfinite(state.history[e].held_out_loss));
  }
  // Noise-free, learnable dynamics: the loss must fall several-fold.
  // Observed: train 1.04 -> 0.076 (14x), held-out (the unseen tail of each
  // log) 0.79 -> 0.24 (3.3x). Requiring 5x and 2x leaves margin for
  // rounding and platform differences yet fails for a loop that does not
  // learn (or learns on the wrong targets).
  EXPECT_LT(last.train_loss, first.train_loss / 5.0);
  EXPECT_LT(last.held_out_loss, held_before / 2.0);
  // The reported held-out loss is evaluate_loss of the final model: same
  // computation, so exactly equal.
  EXPECT_EQ(last.held_out_loss, evaluate_loss(m, s.data, s.split.held_out));
  // One BN update per batch of >= 2 windows (a last batch of 1 is skipped).
  const long n = static_cast<long>(s.split.train.size());
  const long per_epoch = n / 20 + (n % 20 >= 2 ? 1 : 0);
  EXPECT_EQ(m.bn_batches_tracked, 30 * per_epoch);
}

TEST(TrainLoop, DeterministicForASeed) {
  const LoopData s;
  TrainingState a_state, b_state, c_state;
  const HadynetModel a = s.trained(s.options(3), a_state);
  const HadynetModel b = s.trained(s.options(3), b_state);
  EXPECT_TRUE(bit_identical(a.params, b.params));
  for (std::size_t e = 0; e < 3; ++e) {
    EXPECT_EQ(a_state.history[e].train_loss, b_state.history[e].train_loss);
    EXPECT_EQ(a_state.history[e].held_out_loss, b_state.history[e].held_out_loss);
  }
  TrainOptions other = s.options(3);
  other.seed = 4;  // another window order
  EXPECT_FALSE(bit_identical(s.trained(other, c_state).params, a.params));
}

TEST(TrainLoop, ConstantPbKeepsThePbTableExactlyZero) {
  const LoopData s;
  TrainingState state;
  const HadynetModel m = s.trained(s.options(3, /*variable_pb=*/false), state);
  EXPECT_EQ(m.params.pb, RowMatrix<float>::Zero(2, 2));
  EXPECT_NE(m.params.dec_weight, s.fresh.params.dec_weight);  // the weights did train

  TrainingState v_state;
  const HadynetModel v = s.trained(s.options(3, /*variable_pb=*/true), v_state);
  EXPECT_NE(v.params.pb, RowMatrix<float>::Zero(2, 2));  // the control: PB moves when allowed
}

TEST(TrainLoop, RejectsBadOptions) {
  const LoopData s;
  HadynetModel m = s.fresh;
  TrainingState state;
  const auto noop = [](const EpochStats&) {};
  TrainOptions o = s.options(1);
  o.batch = 1;
  EXPECT_THROW(train(m, state, s.data, s.split.train, {}, o, noop), std::invalid_argument);
  o = s.options(0);
  EXPECT_THROW(train(m, state, s.data, s.split.train, {}, o, noop), std::invalid_argument);
  const std::vector<int> one = {0};
  EXPECT_THROW(train(m, state, s.data, one, {}, s.options(1), noop), std::invalid_argument);
  const WindowDataset other_steps(s.seqs, {0, 1}, s.layout, s.norm, 4);  // model trains on 5
  EXPECT_THROW(train(m, state, other_steps, s.split.train, {}, s.options(1), noop),
               std::invalid_argument);
  EXPECT_EQ(state.epochs_done, 0);
}

}  // namespace
}  // namespace hadynet::trainer::testing
