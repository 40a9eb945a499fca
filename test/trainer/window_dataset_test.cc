// Training windows (trainer/window_dataset.h): counts, gathering into the
// network's step-major batch layout, and the held-out split at the tail.
// No tolerances: counts and ids are integers, and gathered values are
// compared bit for bit (see the gather test for why that is exact).
#include "trainer/window_dataset.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <vector>

#include "synthetic_logs.h"

namespace hadynet::trainer::testing {
namespace {

constexpr int kSteps = 4;

struct Data {
  FeatureLayout layout = spring_layout();
  // T = 20, 13, 5 (too short: 5 - 1 - 4 = 0 windows), 30
  std::vector<LogSequence> seqs = {spring_sequence(1.0, 20, 1, "a"), spring_sequence(2.0, 13, 2, "b"),
                                   spring_sequence(3.0, 5, 3, "c"), spring_sequence(4.0, 30, 4, "d")};
  std::vector<int> state = {1, 0, 2, 1};
  Normalization norm = fit_normalization(seqs, layout);
  WindowDataset data{seqs, state, layout, norm, kSteps};
};

TEST(WindowDataset, OneWindowPerStepFromOneToTMinusOneMinusN) {
  const Data d;
  EXPECT_EQ(d.data.steps(), kSteps);
  EXPECT_EQ(d.data.x_dim(), 6);
  EXPECT_EQ(d.data.u_dim(), 2);
  EXPECT_EQ(d.data.y_dim(), 4);
  ASSERT_EQ(d.data.size(), (20 - 1 - kSteps) + (13 - 1 - kSteps) + 0 + (30 - 1 - kSteps));
  // Sequence-major, start ascending from 1; sequence 2 has none.
  int id = 0;
  for (int s : {0, 1, 3}) {
    const int T = d.seqs[static_cast<std::size_t>(s)].steps();
    for (int i = 1; i <= T - 1 - kSteps; ++i, ++id) {
      EXPECT_EQ(d.data.window(id).sequence, s) << id;
      EXPECT_EQ(d.data.window(id).start, i) << id;
    }
  }
}

TEST(WindowDataset, RejectsBadArguments) {
  const Data d;
  EXPECT_THROW(WindowDataset(d.seqs, d.state, d.layout, d.norm, 0), std::invalid_argument);
  EXPECT_THROW(WindowDataset(d.seqs, {0, 1}, d.layout, d.norm, kSteps), std::invalid_argument);
}

TEST(WindowDataset, GatherPutsStandardisedStepsAtStepMajorColumns) {
  const Data d;
  // Windows from different sequences, not in order, one twice.
  const std::vector<int> ids = {20, 0, 14, 7, 0};
  WindowBatch<float> batch;
  Matrix<float> y;
  batch.pb = Matrix<float>::Ones(2, 5);  // gather must clear an explicit PB
  d.data.gather(ids, batch, y);
  const Eigen::Index B = 5;
  ASSERT_EQ(batch.x0.rows(), 6);
  ASSERT_EQ(batch.x0.cols(), B);
  ASSERT_EQ(batch.u.rows(), 2);
  ASSERT_EQ(batch.u.cols(), kSteps * B);
  ASSERT_EQ(y.rows(), 4);
  ASSERT_EQ(y.cols(), kSteps * B);
  EXPECT_EQ(batch.pb.size(), 0);
  ASSERT_EQ(batch.state.size(), 5u);
  // Exact: the reference does the same double operations (subtract, divide)
  // and rounds once to float, as the dataset must.
  for (Eigen::Index b = 0; b < B; ++b) {
    const WindowDataset::Window w = d.data.window(ids[static_cast<std::size_t>(b)]);
    const LogSequence& seq = d.seqs[static_cast<std::size_t>(w.sequence)];
    EXPECT_EQ(batch.state[static_cast<std::size_t>(b)], d.state[static_cast<std::size_t>(w.sequence)]);
    const Eigen::VectorXf x = d.norm.x.standardize(initial_state(d.layout, seq, w.start)).cast<float>();
    EXPECT_EQ(Eigen::VectorXf(batch.x0.col(b)), x) << "window " << b;
    for (int k = 0; k < kSteps; ++k) {
      const Eigen::VectorXf u = d.norm.u.standardize(seq.u.col(w.start + k)).cast<float>();
      const Eigen::VectorXf yk = d.norm.y.standardize(seq.y.col(w.start + k + 1)).cast<float>();
      EXPECT_EQ(Eigen::VectorXf(batch.u.col(k * B + b)), u) << "window " << b << " step " << k;
      EXPECT_EQ(Eigen::VectorXf(y.col(k * B + b)), yk) << "window " << b << " step " << k;
    }
  }
}

TEST(WindowDataset, SplitTailHoldsOutTheTailWithoutSharedRows) {
  const Data d;
  const WindowDataset::Split split = d.data.split_tail(0.25);
  std::set<int> held(split.held_out.begin(), split.held_out.end());
  ASSERT_EQ(held.size(), split.held_out.size());
  for (int id : split.train) EXPECT_EQ(held.count(id), 0u) << id;

  // Per sequence: the held-out windows are the last round(0.25 n); the train
  // windows are exactly those whose rows i-1 .. i+N end before the first
  // held-out window's rows begin.
  for (int s : {0, 1, 3}) {
    std::vector<int> ids;
    for (int id = 0; id < d.data.size(); ++id)
      if (d.data.window(id).sequence == s) ids.push_back(id);
    const int n = static_cast<int>(ids.size());
    const int n_held = static_cast<int>(std::lround(0.25 * n));
    ASSERT_GT(n_held, 0);
    const int first_held_start = d.data.window(ids[static_cast<std::size_t>(n - n_held)]).start;
    std::set<int> held_rows;
    for (int id : ids) {
      const WindowDataset::Window w = d.data.window(id);
      const bool is_held = std::find(split.held_out.begin(), split.held_out.end(), id) != split.held_out.end();
      const bool is_train = std::find(split.train.begin(), split.train.end(), id) != split.train.end();
      EXPECT_EQ(is_held, w.start >= first_held_start) << "sequence " << s << " start " << w.start;
      EXPECT_EQ(is_train, w.start + kSteps < first_held_start - 1)
          << "sequence " << s << " start " << w.start;
      if (is_held)
        for (int r = w.start - 1; r <= w.start + kSteps; ++r) held_rows.insert(r);
    }
    for (int id : split.train) {
      const WindowDataset::Window w = d.data.window(id);
      if (w.sequence != s) continue;
      for (int r = w.start - 1; r <= w.start + kSteps; ++r)
        EXPECT_EQ(held_rows.count(r), 0u) << "sequence " << s << " row " << r << " in both";
    }
  }
  // Something must remain for training in these sequences.
  EXPECT_GT(split.train.size(), 10u);
}

TEST(WindowDataset, SplitTailFractionZeroTrainsOnEverything) {
  const Data d;
  const WindowDataset::Split split = d.data.split_tail(0.0);
  EXPECT_TRUE(split.held_out.empty());
  ASSERT_EQ(static_cast<int>(split.train.size()), d.data.size());
  for (int id = 0; id < d.data.size(); ++id) EXPECT_EQ(split.train[static_cast<std::size_t>(id)], id);
  EXPECT_THROW(d.data.split_tail(1.0), std::invalid_argument);
  EXPECT_THROW(d.data.split_tail(-0.1), std::invalid_argument);
}

}  // namespace
}  // namespace hadynet::trainer::testing
