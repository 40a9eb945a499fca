// A small synthetic dataset with several "dynamics states": a damped
// mass-spring driven by a random force command, one stiffness per state.
//   v' = v + dt (-k q - c v + u),  q' = q + dt v'     (semi-implicit Euler)
// dt = 0.2 s, damping c = 0.6 1/s, k in 1/s^2, u in [-1, 1] (force per mass).
// x = (q, v), y = (q, v) after each step, u = (u). Stable for k < ~90.
#pragma once

#include <cstdint>
#include <vector>

#include "trainer/hadynet_network.h"

namespace hadynet::trainer::testing {

struct DynamicsWindows {
  WindowBatch<float> batch;  // x0 2 x B, u 1 x (N*B), state per window
  Matrix<float> y;           // 2 x (N*B): y_{t+k+1}
};

// For every (stiffness[i], state[i]) one sequence of `sequence_steps` steps
// from a random start, cut into every window of `window_steps` steps.
DynamicsWindows make_dynamics_windows(const std::vector<double>& stiffness,
                                      const std::vector<int>& state, int sequence_steps,
                                      int window_steps, std::uint64_t seed);

}  // namespace hadynet::trainer::testing
