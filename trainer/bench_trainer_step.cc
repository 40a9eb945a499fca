// Times one training step of HADYNET in float on one core at the paper's
// sizes: B = 100 windows, N = 10 steps, hidden 128, x 37, u 8, y 27, pb 8.
// A step is forward (BN training mode) + MSE loss + full BPTT backward.
// Usage: bench_trainer_step [iterations]   (default 300; prints milliseconds)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "trainer/hadynet_network.h"
#include "trainer/hadynet_params.h"

namespace {

using hadynet::trainer::BnMode;
using hadynet::trainer::HadynetDims;
using hadynet::trainer::HadynetGrads;
using hadynet::trainer::HadynetNetwork;
using hadynet::trainer::HadynetParams;
using hadynet::trainer::Matrix;
using hadynet::trainer::WindowBatch;
using Clock = std::chrono::steady_clock;

Matrix<float> random_matrix(std::mt19937_64& rng, int rows, int cols) {
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Matrix<float> m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = normal(rng);
  return m;
}

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Stats {
  double min_ms, median_ms, mean_ms;
};

Stats summarise(std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  double sum = 0.0;
  for (double v : ms) sum += v;
  return {ms.front(), ms[ms.size() / 2], sum / static_cast<double>(ms.size())};
}

}  // namespace

int main(int argc, char** argv) {
  const int iterations = argc > 1 ? std::max(1, std::atoi(argv[1])) : 300;
  const HadynetDims dims{37, 8, 27, 8, 128, 6};
  const int B = 100;
  const int N = 10;

  std::mt19937_64 rng(1);
  HadynetParams<float> params = HadynetParams<float>::initialized(dims, 7);
  WindowBatch<float> batch;
  batch.x0 = random_matrix(rng, dims.x, B);
  batch.u = random_matrix(rng, dims.u, N * B);
  for (int b = 0; b < B; ++b) batch.state.push_back(b % dims.states);
  const Matrix<float> y = random_matrix(rng, dims.y, N * B);

  HadynetNetwork<float> net;
  HadynetGrads<float> grads;
  Matrix<float> d_y_hat;
  std::vector<double> forward_ms;
  std::vector<double> step_ms;
  float loss = 0.0f;
  for (int it = 0; it < iterations + 20; ++it) {  // the first 20 warm up
    const Clock::time_point start = Clock::now();
    const Matrix<float>& y_hat = net.forward(params, batch, BnMode::kTrain);
    loss = hadynet::trainer::mse_loss(y_hat, y, &d_y_hat);
    const double forward_done = ms_since(start);
    net.backward(params, d_y_hat, grads);
    const double step_done = ms_since(start);
    if (it >= 20) {
      forward_ms.push_back(forward_done);
      step_ms.push_back(step_done);
    }
  }
  const Stats f = summarise(forward_ms);
  const Stats s = summarise(step_ms);
  std::printf(
      "bench_trainer_step: float, B=%d N=%d hidden=%d x=%d u=%d y=%d pb=%d, %d iterations\n", B, N,
      dims.hidden, dims.x, dims.u, dims.y, dims.pb, iterations);
  std::printf("Eigen SIMD: %s\n", Eigen::SimdInstructionSetsInUse());
  std::printf("forward+loss           ms: min %.3f  median %.3f  mean %.3f\n", f.min_ms,
              f.median_ms, f.mean_ms);
  std::printf("forward+loss+backward  ms: min %.3f  median %.3f  mean %.3f\n", s.min_ms,
              s.median_ms, s.mean_ms);
  std::printf("(loss %.6f)\n", static_cast<double>(loss));
  return 0;
}
