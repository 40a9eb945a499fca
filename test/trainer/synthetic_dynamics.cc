#include "synthetic_dynamics.h"

#include <array>
#include <random>

#include "test_batches.h"

namespace hadynet::trainer::testing {

namespace {

constexpr double kDt_s = 0.2;
constexpr double kDamping_per_s = 0.6;

}  // namespace

DynamicsWindows make_dynamics_windows(const std::vector<double>& stiffness,
                                      const std::vector<int>& state, int sequence_steps,
                                      int window_steps, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const int per_sequence = sequence_steps - window_steps + 1;
  const int B = per_sequence * static_cast<int>(stiffness.size());
  const int N = window_steps;
  DynamicsWindows out;
  out.batch.x0.resize(2, B);
  out.batch.u.resize(1, N * B);
  out.y.resize(2, N * B);
  int b = 0;
  for (std::size_t s = 0; s < stiffness.size(); ++s) {
    // q[t], v[t] for t = 0..T, u[t] for t = 0..T-1
    std::vector<std::array<double, 2>> x{{uniform(rng, -0.5, 0.5), uniform(rng, -0.5, 0.5)}};
    std::vector<double> u;
    for (int t = 0; t < sequence_steps; ++t) {
      u.push_back(uniform(rng, -1.0, 1.0));
      const auto [q, v] = x.back();
      const double v_next = v + kDt_s * (-stiffness[s] * q - kDamping_per_s * v + u.back());
      x.push_back({q + kDt_s * v_next, v_next});
    }
    for (int start = 0; start < per_sequence; ++start, ++b) {
      out.batch.x0(0, b) = static_cast<float>(x[start][0]);
      out.batch.x0(1, b) = static_cast<float>(x[start][1]);
      out.batch.state.push_back(state[s]);
      for (int k = 0; k < N; ++k) {
        out.batch.u(0, k * B + b) = static_cast<float>(u[start + k]);
        out.y(0, k * B + b) = static_cast<float>(x[start + k + 1][0]);
        out.y(1, k * B + b) = static_cast<float>(x[start + k + 1][1]);
      }
    }
  }
  return out;
}

}  // namespace hadynet::trainer::testing
