// Naive reference of the HADYNET forward pass for tests: plain loops in
// double, one window at a time (BN statistics are the only thing computed
// across windows). It shares no code with trainer/hadynet_network.cc and
// must stay simple: it is what the batched implementation is tested against,
// never "optimised in place".
#pragma once

#include <vector>

#include "trainer/hadynet_network.h"
#include "trainer/hadynet_params.h"

namespace hadynet::trainer::testing {

using Vec = std::vector<double>;

// One window: x0 (dims.x), u[k] (dims.u) for k = 0..N-1, p (dims.pb).
struct RefWindow {
  Vec x0;
  std::vector<Vec> u;
  Vec p;
};

// States of one window: h[k], c[k] for k = 0..N (h[0] = encoder output),
// y[k] = prediction of output k (from h[k+1]).
struct RefTrace {
  std::vector<Vec> h;
  std::vector<Vec> c;
  std::vector<Vec> y;
};

// Converts a batched input; PB rows are read from params.pb when the batch
// uses state indices.
std::vector<RefWindow> to_reference(const WindowBatch<double>& batch,
                                    const HadynetParams<double>& params);

// The forward pass of every window. kTrain: BN with the mean and the biased
// variance of the encoder pre-activations over the windows.
std::vector<RefTrace> reference_forward(const HadynetParams<double>& params,
                                        const std::vector<RefWindow>& windows, BnMode mode);

// Outputs of the truncated computation graph, for finite differences of the
// truncated objective: output k of window b starts from the constant state
// frozen[b].h/c[s], s = k-K+1, when s >= 1, and otherwise from the live
// encoder (c_0 = 0); it then runs LSTM steps s..k with `params`.
// At params equal to those of `frozen`, the values equal the plain forward.
std::vector<std::vector<Vec>> reference_truncated_outputs(const HadynetParams<double>& params,
                                                          const std::vector<RefWindow>& windows,
                                                          BnMode mode, int truncation,
                                                          const std::vector<RefTrace>& frozen);

}  // namespace hadynet::trainer::testing
