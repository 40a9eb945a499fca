// The encoder's batch norm folded into its weights, as the firmware runs it
// (codegen writes the folded weights). Part of the portable deploy-math
// library (hadynet_deploy_math): the same bits on every x86-64.
#pragma once

#include "trainer/hadynet_params.h"

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

}  // namespace hadynet::trainer
