// Preparing a trained model for codegen (issue 4): batch norm folded into the
// encoder, and the value ranges of every tensor the firmware computes, from
// which codegen picks per-tensor fixed-point formats.
#pragma once

#include <Eigen/Core>
#include <span>

#include "trainer/hadynet_model.h"
#include "trainer/window_dataset.h"

namespace hadynet::trainer {

// Encoder with eval-mode batch norm folded in:
//   BN(W z + b) = s .* (W z + b - mean) + beta,  s = gamma / sqrt(running_var + eps)
//             = (diag(s) W) z + s .* (b - mean) + beta
// so h_0 = ReLU(weight [x ; p] + bias). Exact in real arithmetic; in float the
// folded forward differs from the BN forward by rounding only.
struct FoldedEncoder {
  RowMatrix<float> weight;  // hidden x (x + pb)
  Vector<float> bias;       // hidden
};
FoldedEncoder fold_batch_norm(const HadynetParams<float>& params);

// Largest absolute value of each quantity the firmware's forward computes,
// over the windows `ids` of `data` with their states' PBs (BN eval), in
// standardised units. Weights' ranges are read from the parameters.
struct ValueRanges {
  double x = 0, u = 0, pb = 0;          // inputs
  double enc_pre = 0;                   // folded encoder pre-activation (before ReLU)
  double h = 0;                         // h_0 .. h_N
  double gate_pre = 0;                  // LSTM gate pre-activations (all four gates)
  double c = 0;                         // cell states
  double y = 0;                         // decoder outputs
  double enc_weight = 0, lstm_weight = 0, dec_weight = 0;  // folded / raw weights
  double enc_bias = 0, lstm_bias = 0, dec_bias = 0;
};
ValueRanges measure_ranges(const HadynetModel& model, const WindowDataset& data,
                           std::span<const int> ids);

}  // namespace hadynet::trainer
