// Multiply-accumulate counts of the core's jobs for a generated model: the
// denominators of the benchmarks' instructions-per-MAC and MACs-per-second
// figures. Counted from the algorithms in hadynet_net.h, detector.h,
// grasp_stabilizer.h and pb_adapter.h (matrix-vector products only; element-wise gate
// arithmetic, activations and the loss are a few per unit and not counted).
#ifndef HADYNET_FIRMWARE_CORE_MAC_COUNT_H_
#define HADYNET_FIRMWARE_CORE_MAC_COUNT_H_

#include "firmware/core/model_contract.h"

namespace hadynet::firmware {

template <GeneratedModel M>
struct MacCount {
  static constexpr long kH = M::kHidden, kGates = 4L * M::kHidden;
  // h_0 = ReLU(W_enc [x ; p] + b)
  static constexpr long encode = kH * (M::kX + M::kPb);
  // gates = W_ih [u ; p] + W_hh h + b, then y = W_dec h'
  static constexpr long lstm_step = kGates * (M::kU + M::kPb + kH);
  static constexpr long decode = static_cast<long>(M::kY) * kH;
  static constexpr long step = lstm_step + decode;  // one HADYNET step (y from u)
  // Detection: encode x_{t-N}, N steps, whitening W (e - mu).
  static constexpr long detect = encode + M::kDetectSteps * step + static_cast<long>(M::kY) * M::kY;

  // Back-propagation of one LSTM step to u (W_ih[:, :U]^T) and, unless it is
  // the last step of a stream, to h (W_hh^T); plus the decoder W_dec^T of
  // each output.
  static constexpr long backward_u = kGates * M::kU;
  static constexpr long backward_h = kGates * kH;
  static constexpr long backward_decoder = decode;

  // One gradient of the stabiliser over horizon Hc with truncation depth K.
  static constexpr long gradient(int truncation) {
    const long hc = M::kControlHorizon;
    if (truncation >= hc) {  // one sweep; h of step 0 is not propagated
      return hc * (backward_decoder + backward_u) + (hc - 1) * backward_h;
    }
    long total = 0;
    for (long k = 0; k < hc; ++k) {
      const long depth = k + 1 < truncation ? k + 1 : truncation;  // steps k .. k-depth+1
      total += backward_decoder + depth * backward_u + (depth - 1) * backward_h;
    }
    return total;
  }
  // One control period in the worst case (no early stop): encode x_t, the
  // hold rollout of the relative reference (GraspStabilizer::Reference), the
  // warm start's rollout, then per epoch one gradient and N_batch rollouts.
  static constexpr long control(int epochs, int truncation, bool relative_reference = true) {
    const long rollout = M::kControlHorizon * step;
    return encode + (relative_reference ? rollout : 0) + rollout +
           epochs * (gradient(truncation) + M::kControlAlphaCount * rollout);
  }
  static constexpr long control_default = control(M::kControlEpochs, M::kControlTruncation);
  // The firmware's period in control mode: detection plus the stabiliser.
  static constexpr long period_control = detect + control_default;

  // PB adaptation (pb_adapter.h), one window: encode and N_train steps
  // forward; back through every step to the PB (W_ih[:, U:]^T), to h
  // (W_hh^T, down to h_0) and the decoder, then the encoder's PB columns.
  static constexpr long backward_pb = kGates * M::kPb;
  static constexpr long adapt_window =
      encode + M::kTrainSteps * (step + backward_decoder + backward_pb + backward_h) + kH * M::kPb;
  // A detect-mode period that also runs `windows` adaptation windows.
  static constexpr long period_adapt(int windows) { return detect + windows * adapt_window; }
};

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_MAC_COUNT_H_
