// Stateful, step-by-step HADYNET forward pass of a generated model
// (docs/method.md, "Network"), in the model's numerics (q15 or f32), plus the
// back-propagation through time the grasp stabiliser (to the commands) and
// PB adaptation (to the PB, pb_adapter.h) need.
//
//   encode:  h_0 = ReLU(W_enc' [x ; p] + b_enc')   (batch norm folded by codegen), c_0 = 0
//   step:    [i f g o] = act(W_ih [u ; p] + W_hh h + b),  c' = f c + i g,  h' = o tanh(c')
//            y = W_dec h' + b_dec
//
// Every value is in standardised units (model_contract.h); the q15 formats
// are the model's kFrac* constants. Allocation-free: all state is in the
// object, sized by the model at compile time; no call allocates or throws.
#ifndef HADYNET_FIRMWARE_CORE_HADYNET_NET_H_
#define HADYNET_FIRMWARE_CORE_HADYNET_NET_H_

#include <cstdint>

#include "firmware/core/kernels/dot_q15.h"
#include "firmware/core/model_contract.h"
#include "firmware/core/model_tensors.h"
#include "firmware/core/numerics.h"

namespace hadynet::firmware {

// What the backward pass needs from one LSTM step.
template <GeneratedModel M>
struct StepTrace {
  using Value = typename M::Value;
  Value gates[4 * M::kHidden];  // activated i, f, g, o (Q15)
  Value c_prev[M::kHidden];     // c before the step (Q(kFracC))
  Value tanh_c[M::kHidden];     // tanh(c after the step) (Q15)
};

template <GeneratedModel M>
class HadynetNet {
 public:
  static_assert(M::kContractVersion == kModelContractVersion,
                "generated model was written for another contract version: re-run codegen");
  using N = Numerics<M>;
  using Value = typename M::Value;
  using Grad = typename N::Grad;
  static constexpr int kX = M::kX, kU = M::kU, kY = M::kY, kPb = M::kPb, kH = M::kHidden;
  static constexpr int kGates = 4 * kH;
  static constexpr int kFracOut = N::kFixed ? 15 : 0;  // activation outputs
  static_assert(sizeof(ModelTensors<M>) == unpadded_tensor_bytes<M>(),
                "ModelTensors has interior padding: its bytes would differ between targets");

  // Runs on `tensors` (the compiled-in model by default, or a model slot's
  // payload in flash), which must outlive the net.
  explicit constexpr HadynetNet(const ModelTensors<M>& tensors = kCompiledTensors<M>) noexcept : t_(&tensors) {}
  const ModelTensors<M>& tensors() const noexcept { return *t_; }

  // h_0 from the standardised initial state x (Q(kFracIn)) and PB p
  // (Q(kFracIn)); c_0 = 0. p is kept for the following steps.
  void encode(const Value (&x)[kX], const Value (&pb)[kPb]) noexcept {
    for (int i = 0; i < kPb; ++i) pb_[i] = pb[i];
    if constexpr (N::kFixed) {
      // [x ; p] as one vector (zero-padded to the packed matrix's columns):
      // one exact dot product per row, requantised by the build's kernel.
      const auto& enc = t_->weights.enc;
      alignas(8) Value xp[decltype(NetworkWeights<M>::enc)::kCols] = {};
      for (int i = 0; i < kX; ++i) xp[i] = x[i];
      for (int i = 0; i < kPb; ++i) xp[kX + i] = pb_[i];
      constexpr int kFrom = M::kFracEncW + M::kFracIn;
      static_assert(kFrom >= M::kFracH, "the encoder output has more fractional bits than its sum");
      kernels::matvec_requantize_q15({enc.data, enc.kCols, xp, 0}, {}, t_->enc_bias, kH, kFrom - M::kFracH, h_);
      for (int r = 0; r < kH; ++r) {
        h_[r] = h_[r] > 0 ? h_[r] : Value{0};
        c_[r] = 0;
      }
    } else {
      for (int r = 0; r < kH; ++r) {
        const auto acc = typename N::Acc{t_->enc_bias[r]} + N::dot(t_->weights.enc[r], x, kX) +
                         N::dot(t_->weights.enc[r] + kX, pb_, kPb);
        const Value v = N::template narrow<M::kFracEncW + M::kFracIn, M::kFracH>(acc);
        h_[r] = v > 0 ? v : Value{0};
        c_[r] = 0;
      }
    }
  }

  // One LSTM step with command u (Q(kFracIn)); writes y (Q(kFracY)). If
  // `trace` is not null it receives what backward() needs for this step.
  void step(const Value (&u)[kU], Value (&y)[kY], StepTrace<M>* trace = nullptr) noexcept {
    // The gates go straight into the trace when there is one.
    Value gates_local[kGates];
    Value* const gates = trace != nullptr ? trace->gates : gates_local;
    constexpr int kAccFrac = M::kFracLstmAcc;
    constexpr int kInShift = kAccFrac - (M::kFracLstmW + M::kFracIn);
    constexpr int kHShift = kAccFrac - (M::kFracLstmW + M::kFracH);
    static_assert(!N::kFixed || (kInShift >= 0 && kHShift >= 0), "kFracLstmAcc too small");
    if constexpr (N::kFixed) {
      // gates = requantise(b + W_ih [u;p] 2^kInShift + W_hh h 2^kHShift) by
      // the build's kernel. Exact: both products are brought to
      // Q(kFracLstmAcc) by left shifts (|sum| < 2^46 before the shift of at
      // most 15 bits), then one rounding to Q(kFracGate).
      static_assert(kAccFrac >= M::kFracGate, "gate sums have fewer fractional bits than the gates");
      const NetworkWeights<M>& kw = t_->weights;
      // [u ; p]: one dot product per row of W_ih.
      alignas(8) Value up[decltype(NetworkWeights<M>::ih)::kCols] = {};
      for (int i = 0; i < kU; ++i) up[i] = u[i];
      for (int i = 0; i < kPb; ++i) up[kU + i] = pb_[i];
      alignas(8) Value h_buffer[kHPadded];
      kernels::matvec_requantize_q15({kw.ih.data, kw.ih.kCols, up, kInShift},
                                     {kw.hh.data, kw.hh.kCols, hidden_padded(h_buffer), kHShift}, t_->lstm_bias,
                                     kGates, kAccFrac - M::kFracGate, gates);
      kernels::sigmoid_q15_block(gates, 2 * kH);       // i, f
      kernels::tanh_q15_block(gates + 2 * kH, kH);     // g
      kernels::sigmoid_q15_block(gates + 3 * kH, kH);  // o
    } else {
      for (int r = 0; r < kGates; ++r) {
        const auto in = N::dot(t_->weights.ih[r], u, kU) + N::dot(t_->weights.ih[r] + kU, pb_, kPb);
        const auto rec = N::dot(t_->weights.hh[r], h_, kH);
        const Value pre = N::template narrow<kAccFrac, M::kFracGate>(t_->lstm_bias[r] + in + rec);
        gates[r] = (r >= 2 * kH && r < 3 * kH) ? N::tanh(pre) : N::sigmoid(pre);
      }
    }
    // c' = f c + i g, h' = o tanh(c'); the tanh of all units in one block.
    Value tanh_c_local[kH];
    Value* const tc = trace != nullptr ? trace->tanh_c : tanh_c_local;
    if (trace != nullptr) {
      for (int j = 0; j < kH; ++j) trace->c_prev[j] = c_[j];
    }
    if constexpr (N::kFixed) {
      constexpr int C = M::kFracC;
      static_assert(C <= 15, "c is int16");
      for (int j = 0; j < kH; ++j) {
        // f c + i g with one rounding (Q(15 + C) and Q30 products, exact).
        c_[j] = fixed::bounded::cell_update<C>(gates[kH + j], c_[j], gates[j], gates[2 * kH + j]);
        tc[j] = fixed::bounded::rescale_i16<C, M::kFracGate>(c_[j]);
      }
      kernels::tanh_q15_block(tc, kH);
      for (int j = 0; j < kH; ++j) h_[j] = fixed::bounded::mul<kFracOut, kFracOut, M::kFracH>(gates[3 * kH + j], tc[j]);
    } else {
      for (int j = 0; j < kH; ++j) {
        const Value i = gates[j], f = gates[kH + j], g = gates[2 * kH + j], o = gates[3 * kH + j];
        c_[j] = f * c_[j] + i * g;
        tc[j] = N::tanh(c_[j]);
        h_[j] = o * tc[j];
      }
    }
    decode(y);
  }

  // Contact simulation: N steps from the current state with commands
  // u[0..N) (Q(kFracIn)), predictions y[k] of step k (Q(kFracY)).
  template <int Steps>
  void rollout(const Value (&u)[Steps][kU], Value (&y)[Steps][kY]) noexcept {
    for (int k = 0; k < Steps; ++k) step(u[k], y[k]);
  }

  // y = W_dec h + b_dec of the current hidden state.
  void decode(Value (&y)[kY]) const noexcept {
    if constexpr (N::kFixed) {
      constexpr int kFrom = M::kFracDecW + M::kFracH;
      static_assert(kFrom >= M::kFracY, "the decoder output has more fractional bits than its sum");
      const auto& dec = t_->weights.dec;
      alignas(8) Value h_buffer[kHPadded];
      kernels::matvec_requantize_q15({dec.data, dec.kCols, hidden_padded(h_buffer), 0}, {}, t_->dec_bias, kY,
                                     kFrom - M::kFracY, y);
    } else {
      for (int r = 0; r < kY; ++r) {
        const auto acc = typename N::Acc{t_->dec_bias[r]} + N::dot(t_->weights.dec[r], h_, kH);
        y[r] = N::template narrow<M::kFracDecW + M::kFracH, M::kFracY>(acc);
      }
    }
  }

  // One step of back-propagation through the LSTM, for input gradients only
  // (weights are constant). Given dL/dh' (dh) and dL/dc' (dc) after step
  // `trace`, adds dL/du of that step to du (kU entries) and, if dh_prev is
  // not null, writes dL/dh and dL/dc before the step into dh_prev / dc
  // (dc is updated in place). Gradients share one scale (numerics.h).
  void backward_step(const StepTrace<M>& trace, const Grad (&dh)[kH], Grad (&dc)[kH],
                     Grad (&du)[kU], Grad* dh_prev) noexcept {
    Grad dgates[kGates];
    gate_gradients(trace, dh, dc, dgates);
    // The chain rule runs on real values: a gradient's raw value is its real
    // value times one constant; products with a Q(F) operand divide by 2^F
    // (grad_mul<F>; the W^T products requantised from Q(F)), so the constant
    // never changes.
    // Requantising a pre-activation is the identity on reals (saturation is
    // not differentiated).
    if constexpr (N::kFixed) {
      // dgates as block floating point, for W_ih's command columns (the
      // packed matrix's first columns) and W_hh^T: exact int64 sums of the
      // mantissas, one rounding per output.
      const BlockGrad<kGates> block(dgates);
      const auto& ih = t_->weights.ih;
      kernels::dot_cols_packed_q15(ih.data, ih.kCols, kGates, block.mantissa, kU, scratch_);
      for (int k = 0; k < kU; ++k)
        du[k] = N::grad_add(du[k], fixed::bounded::requantize_i32<M::kFracLstmW, 0>(block.scaled(scratch_[k])));
      if (dh_prev != nullptr) hidden_gradient(block, dh_prev);
    } else {
      Grad du_step[kU];
      N::template transposed_matvec<M::kFracLstmW>(t_->weights.ih, dgates, kU, du_step, scratch_);
      for (int k = 0; k < kU; ++k) du[k] = N::grad_add(du[k], du_step[k]);
      if (dh_prev != nullptr) hidden_gradient(dgates, dh_prev);
    }
  }

  // The same step of back-propagation for the PB instead of the command
  // (PB adaptation, pb_adapter.h): adds dL/dp of this step (the PB enters
  // every step through W_ih's last kPb columns) to dpb, and writes dh_prev /
  // dc as backward_step.
  void backward_step_pb(const StepTrace<M>& trace, const Grad (&dh)[kH], Grad (&dc)[kH],
                        Grad (&dpb)[kPb], Grad* dh_prev) noexcept {
    Grad dgates[kGates];
    gate_gradients(trace, dh, dc, dgates);
    if constexpr (N::kFixed) {
      // dgates as block floating point, for the PB columns and W_hh^T.
      const BlockGrad<kGates> block(dgates);
      const auto& ih = t_->weights.ih;
      if constexpr (kU % 8 == 0) {
        // The PB columns start a chunk of the packed matrix: the packed
        // kernel reads them from that chunk on (packed_index is linear in it).
        kernels::dot_cols_packed_q15(ih.data + (kU / 8) * 16, ih.kCols, kGates, block.mantissa, kPb, scratch_);
      } else {
        for (int i = 0; i < kPb; ++i) scratch_[i] = 0;
        for (int r = 0; r < kGates; ++r)
          for (int i = 0; i < kPb; ++i)
            scratch_[i] += std::int64_t{ih.data[kernels::packed_index(ih.kCols, r, kU + i)]} * block.mantissa[r];
      }
      for (int i = 0; i < kPb; ++i)
        dpb[i] = N::grad_add(dpb[i], fixed::bounded::requantize_i32<M::kFracLstmW, 0>(block.scaled(scratch_[i])));
      if (dh_prev != nullptr) hidden_gradient(block, dh_prev);
    } else {
      for (int i = 0; i < kPb; ++i) scratch_[i] = 0;
      for (int r = 0; r < kGates; ++r) {
        if (dgates[r] == 0) continue;
        for (int i = 0; i < kPb; ++i) scratch_[i] += t_->weights.ih[r][kU + i] * dgates[r];
      }
      for (int i = 0; i < kPb; ++i) dpb[i] += scratch_[i];
      if (dh_prev != nullptr) hidden_gradient(dgates, dh_prev);
    }
  }

  // dL/dp through the encoder, h_0 = ReLU(W_enc [x ; p] + b): adds
  // W_enc[:, kX:]^T (dh0 where h0 > 0) to dpb. h0 is the encoder's output
  // (save() right after encode()); dh0 the gradient reaching it.
  void backward_encoder_pb(const Value (&h0)[kH], const Grad (&dh0)[kH], Grad (&dpb)[kPb]) noexcept {
    for (int i = 0; i < kPb; ++i) scratch_[i] = 0;
    for (int r = 0; r < kH; ++r) {
      if (!(h0[r] > 0) || dh0[r] == 0) continue;  // ReLU: no gradient where it is off
      for (int i = 0; i < kPb; ++i) {
        if constexpr (N::kFixed) {
          const auto& enc = t_->weights.enc;
          scratch_[i] += std::int64_t{enc.data[kernels::packed_index(enc.kCols, r, kX + i)]} * dh0[r];
        } else {
          scratch_[i] += t_->weights.enc[r][kX + i] * dh0[r];
        }
      }
    }
    for (int i = 0; i < kPb; ++i) {
      if constexpr (N::kFixed) {
        dpb[i] = N::grad_add(dpb[i], fixed::requantize_i32<M::kFracEncW, 0>(scratch_[i]));
      } else {
        dpb[i] += scratch_[i];
      }
    }
  }

  // dh += W_dec^T dy (dy: dL/dy of the current output, kY entries).
  void backward_decoder(const Grad (&dy)[kY], Grad (&dh)[kH]) noexcept {
    Grad d[kH];
    if constexpr (N::kFixed) {
      const auto& dec = t_->weights.dec;
      const BlockGrad<kY> block(dy);
      kernels::dot_cols_packed_q15(dec.data, dec.kCols, kY, block.mantissa, kH, scratch_);
      for (int j = 0; j < kH; ++j) d[j] = fixed::bounded::requantize_i32<M::kFracDecW, 0>(block.scaled(scratch_[j]));
    } else {
      N::template transposed_matvec<M::kFracDecW>(t_->weights.dec, dy, kH, d, scratch_);
    }
    for (int j = 0; j < kH; ++j) dh[j] = N::grad_add(dh[j], d[j]);
  }

  // State access (for rollouts that restart from h_0 and for tests).
  struct State {
    Value h[kH];
    Value c[kH];
  };
  void save(State& s) const noexcept {
    for (int j = 0; j < kH; ++j) {
      s.h[j] = h_[j];
      s.c[j] = c_[j];
    }
  }
  void restore(const State& s) noexcept {
    for (int j = 0; j < kH; ++j) {
      h_[j] = s.h[j];
      c_[j] = s.c[j];
    }
  }
  const Value (&hidden() const noexcept)[kH] { return h_; }
  const Value (&cell() const noexcept)[kH] { return c_; }

 private:
  // dL/d(gate pre-activations) of the step `trace` from dh and dc after it;
  // dc becomes dL/dc before the step.
  void gate_gradients(const StepTrace<M>& trace, const Grad (&dh)[kH], Grad (&dc)[kH],
                      Grad (&dgates)[kGates]) const noexcept {
    for (int j = 0; j < kH; ++j) {
      const Value i = trace.gates[j], f = trace.gates[kH + j], g = trace.gates[2 * kH + j],
                  o = trace.gates[3 * kH + j], tc = trace.tanh_c[j];
      // h' = o tanh(c'): do = dh tanh(c'), dc' += dh o tanh'(c').
      const Grad d_o = N::template grad_mul<kFracOut>(dh[j], tc);
      const Grad dcj = N::grad_add(
          dc[j], N::grad_mul_q15(N::template grad_mul<kFracOut>(dh[j], o), N::tanh_slope(tc)));
      // c' = f c + i g.
      dgates[j] = N::grad_mul_q15(N::template grad_mul<kFracOut>(dcj, g), N::sigmoid_slope(i));
      dgates[kH + j] =
          N::grad_mul_q15(N::template grad_mul<M::kFracC>(dcj, trace.c_prev[j]), N::sigmoid_slope(f));
      dgates[2 * kH + j] = N::grad_mul_q15(N::template grad_mul<kFracOut>(dcj, i), N::tanh_slope(g));
      dgates[3 * kH + j] = N::grad_mul_q15(d_o, N::sigmoid_slope(o));
      dc[j] = N::template grad_mul<kFracOut>(dcj, f);
    }
  }

  // q15: n gradients as block floating point (numerics.h, grad_block_q15),
  // as the packed W^T kernel reads them: int16 mantissas, an odd count
  // padded with a zero, and the exponent.
  template <int n>
  struct BlockGrad {
    alignas(4) std::int16_t mantissa[n + n % 2];  // word-aligned: the kernels read pairs
    int shift;
    explicit BlockGrad(const Grad (&g)[n]) noexcept : shift(grad_block_q15(g, n, mantissa)) {
      if constexpr (n % 2 != 0) mantissa[n] = 0;
    }
    // A sum over mantissas back at the gradients' scale (exact). With at
    // most 2^13 terms of |W m| <= 2^30 and s <= 17 it stays below 2^60,
    // inside fixed::bounded's domain.
    static_assert(n <= 8192, "scaled sums must stay below 2^62 (fixed::bounded)");
    std::int64_t scaled(std::int64_t sum) const noexcept { return sum * (std::int64_t{1} << shift); }
  };

  // dh_prev = W_hh^T dgates (dL/dh before the step); q15 from the gate
  // gradients' block floating point.
  void hidden_gradient(const Grad (&dgates)[kGates], Grad* dh_prev) noexcept
    requires(!N::kFixed)
  {
    N::template transposed_matvec<M::kFracLstmW>(t_->weights.hh, dgates, kH, dh_prev, scratch_);
  }
  void hidden_gradient(const BlockGrad<kGates>& block, Grad* dh_prev) noexcept
    requires N::kFixed
  {
    const NetworkWeights<M>& kw = t_->weights;
    kernels::dot_cols_packed_q15(kw.hh.data, kw.hh.kCols, kGates, block.mantissa, kH, scratch_);
    for (int j = 0; j < kH; ++j) dh_prev[j] = fixed::bounded::requantize_i32<M::kFracLstmW, 0>(block.scaled(scratch_[j]));
  }

  // q15: h as the packed kernels read it, kH values then zeros up to a
  // multiple of 8 (they meet the packed matrices' zero columns): h_ itself,
  // or a copy in `buffer` if kH is not a multiple of 8.
  static constexpr int kHPadded = (kH + 7) / 8 * 8;
  const Value* hidden_padded(Value (&buffer)[kHPadded]) const noexcept {
    if constexpr (kH == kHPadded) {
      return h_;
    } else {
      for (int j = 0; j < kHPadded; ++j) buffer[j] = j < kH ? h_[j] : Value{0};
      return buffer;
    }
  }

  const ModelTensors<M>* t_;
  Value pb_[kPb] = {};
  Value h_[kH] = {};
  Value c_[kH] = {};
  static constexpr int kScratch = kH > kU ? (kH > kPb ? kH : kPb) : (kU > kPb ? kU : kPb);
  typename N::GradAcc scratch_[kScratch] = {};
};

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_HADYNET_NET_H_
