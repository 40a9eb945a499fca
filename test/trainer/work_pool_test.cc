// trainer/work_pool.h: every chunk runs exactly once whatever the threads,
// and the network's results are bit-identical for any thread count (the
// split of the work never depends on it).
#include "trainer/work_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <vector>

#include "test_batches.h"
#include "trainer/hadynet_network.h"

namespace hadynet::trainer::testing {
namespace {

TEST(WorkPool, EveryChunkRunsExactlyOnce) {
  for (int threads : {1, 2, 5}) {
    WorkPool pool(threads);
    for (int chunks : {0, 1, 2, 7, 1000}) {
      for (int repeat = 0; repeat < 50; ++repeat) {  // many jobs: stale claims must never land
        std::vector<std::atomic<int>> runs(static_cast<std::size_t>(chunks));
        pool.run(chunks, [&](int i) { runs[static_cast<std::size_t>(i)].fetch_add(1); });
        for (int i = 0; i < chunks; ++i) {
          ASSERT_EQ(runs[static_cast<std::size_t>(i)].load(), 1)
              << threads << " threads, chunk " << i << " of " << chunks << ", job " << repeat;
        }
      }
    }
  }
}

TEST(WorkPool, RejectsNoThreads) { EXPECT_THROW(WorkPool(0), std::invalid_argument); }

// Forward (BN train) and backward at the paper's sizes and batch, with 1 to
// 5 training threads: the outputs and every gradient are the same bits.
TEST(WorkPool, NetworkResultsDoNotDependOnTheThreadCount) {
  const HadynetDims dims{.x = 37, .u = 8, .y = 27, .pb = 8, .hidden = 128, .states = 5};  // the paper's sizes
  const HadynetParams<float> params = generic_params(dims, 11).cast<float>();
  const WindowBatch<double> batch_d = random_batch(dims, 100, 10, 12, {0, 1, 2, 3, 4});
  WindowBatch<float> batch;
  batch.x0 = batch_d.x0.cast<float>();
  batch.u = batch_d.u.cast<float>();
  batch.state = batch_d.state;
  std::vector<Matrix<float>> y_hats;
  std::vector<HadynetGrads<float>> grads;
  for (int threads : {1, 2, 3, 4, 5}) {  // 1, 4, 6, 8 and 10 chunks
    set_training_threads(threads);
    HadynetNetwork<float> net;
    const Matrix<float> y_hat = net.forward(params, batch, BnMode::kTrain);
    HadynetGrads<float> g;
    net.backward(params, Matrix<float>::Constant(y_hat.rows(), y_hat.cols(), 1e-3f) + 0.01f * y_hat, g, 4);
    y_hats.push_back(y_hat);
    grads.push_back(std::move(g));
  }
  set_training_threads(1);
  for (std::size_t i = 1; i < y_hats.size(); ++i) {
    EXPECT_EQ(std::memcmp(y_hats[i].data(), y_hats[0].data(), sizeof(float) * static_cast<std::size_t>(y_hats[0].size())), 0);
    EXPECT_TRUE(bit_identical(grads[i].params, grads[0].params)) << "thread count index " << i;
    EXPECT_EQ(std::memcmp(grads[i].u.data(), grads[0].u.data(), sizeof(float) * static_cast<std::size_t>(grads[0].u.size())), 0);
  }
}

}  // namespace
}  // namespace hadynet::trainer::testing
