// Deterministic random parameters and batches for the trainer tests.
#pragma once

#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "trainer/hadynet_network.h"
#include "trainer/hadynet_params.h"

namespace hadynet::trainer::testing {

// True if both parameter sets have the same dims and every tensor has the
// same bytes (no tolerance: for determinism and round-trip tests).
template <class S>
bool bit_identical(const HadynetParams<S>& a, const HadynetParams<S>& b) {
  if (!(a.dims == b.dims)) return false;
  const auto ta = a.tensors();
  const auto tb = b.tensors();
  for (std::size_t i = 0; i < ta.size(); ++i) {
    if (ta[i].size() != tb[i].size() ||
        std::memcmp(ta[i].data, tb[i].data, sizeof(S) * static_cast<std::size_t>(ta[i].size())) != 0)
      return false;
  }
  return true;
}

// Uniform in [lo, hi) from the top 53 bits of the generator.
inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

inline Matrix<double> random_matrix(std::mt19937_64& rng, int rows, int cols, double scale = 1.0) {
  Matrix<double> m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = uniform(rng, -scale, scale);
  return m;
}

// PyTorch-style initialisation, then every "constant" initial value made
// generic so that no gradient path is trivially zero or one: BN weight in
// [0.5, 1.5], BN bias in [-0.3, 0.3], running mean in [-0.2, 0.2], running
// var in [0.5, 1.5], PB in [-0.5, 0.5].
inline HadynetParams<double> generic_params(const HadynetDims& dims, std::uint64_t seed) {
  HadynetParams<double> p = HadynetParams<double>::initialized(dims, seed);
  std::mt19937_64 rng(seed ^ 0x5eedULL);
  for (Eigen::Index i = 0; i < p.enc_bn_weight.size(); ++i) {
    p.enc_bn_weight(i) = uniform(rng, 0.5, 1.5);
    p.enc_bn_bias(i) = uniform(rng, -0.3, 0.3);
    p.enc_bn_running_mean(i) = uniform(rng, -0.2, 0.2);
    p.enc_bn_running_var(i) = uniform(rng, 0.5, 1.5);
  }
  for (Eigen::Index i = 0; i < p.pb.size(); ++i) p.pb.data()[i] = uniform(rng, -0.5, 0.5);
  return p;
}

// B windows of N steps with inputs in [-1, 1]; window b uses state states[b % size].
inline WindowBatch<double> random_batch(const HadynetDims& dims, int B, int N, std::uint64_t seed,
                                        const std::vector<int>& states) {
  std::mt19937_64 rng(seed);
  WindowBatch<double> batch;
  batch.x0 = random_matrix(rng, dims.x, B);
  batch.u = random_matrix(rng, dims.u, N * B);
  for (int b = 0; b < B; ++b) batch.state.push_back(states[b % states.size()]);
  return batch;
}

}  // namespace hadynet::trainer::testing
