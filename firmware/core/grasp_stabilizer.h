// Grasp stabiliser (seed paper section III-F; docs/method.md, "Grasp stabiliser"): every control
// period, optimise the command sequence u_seq = u_[t, t+H) so that HADYNET's
// predicted y_[t+1, t+H] stays at the reference y_ref (y at grasp start):
//
//   L   = sum_k sum_i w_i (y_est,k,i - r_k,i)^2
//         w_i = kLossWeightUp[i] where y_est >= r, else kLossWeightDown[i]
//         (force channels: 1 / beta; angles: w2; lengths: w3; others 0;
//         codegen folds std_i^2 in, so L is in the paper's physical units)
//   g   = dL/du_seq by back-propagation through time (truncation depth K:
//         each output's gradient flows back through at most K LSTM steps);
//         entries of commands the model marks inactive are zeroed
//   u_seq <- the best of u_seq - alpha_j g / |g|, j = 1..N_batch
//   repeated N_epoch times; the first entry is the command. The next period
//   starts from this sequence shifted by one step, last entry repeated.
//
// Derived inputs (model_contract.h, DerivedKind) are never planned. An input
// dead time's lag input (kLag, lag d, of base command b) at horizon step k is
// the base command d steps earlier: the plan's u_b,k-d for k >= d, the
// command already applied for k < d (set_lag_history), mapped from b's
// standardisation to the lag slot's. Its gradient flows back to u_b,k-d, so
// the plan sees a command act d steps later. The other derived inputs (signs
// and hysteresis of a command or of its change) keep their value of now over
// the horizon (hold_input): they are steps of the commands, with no gradient.
//
// Two choices differ from the paper's text, both measured on the plant
// (docs/firmware.md, "grasp stabiliser"), both switchable in Settings:
//  * the reference r_k: by default relative to holding still (Reference),
//    which removes the model's absolute prediction bias from L; the paper's
//    r_k = y_ref drove the grasp away on every state we tried;
//  * a step is only taken if it lowers L (monotone line search); the paper
//    adopts the best step size even when L rises, which lets the plan drift.
//
// Numerics. q15: L is an exact int64 sum; dL/dy is scaled so that its
// largest entry is 2^kGradFracBits (the gradient's direction is all that is
// used), then propagated in int32 (numerics.h); |g| is an integer square
// root; g/|g| is rounded to Q15. f32: the same in float.
// Memory: two rollout traces of H steps (the current sequence and the
// candidate being tried), all inside the object; nothing allocated.
#ifndef HADYNET_FIRMWARE_CORE_GRASP_STABILIZER_H_
#define HADYNET_FIRMWARE_CORE_GRASP_STABILIZER_H_

#include <cmath>
#include <cstdint>

#include "firmware/core/hadynet_net.h"
#include "firmware/core/isqrt.h"
#include "firmware/core/model_contract.h"

namespace hadynet::firmware {

template <GeneratedModel M>
class GraspStabilizer {
 public:
  using N = Numerics<M>;
  using Value = typename M::Value;
  using Grad = typename N::Grad;
  static constexpr int kHorizon = M::kControlHorizon;
  static constexpr int kAlphas = M::kControlAlphaCount;
  static constexpr int kU = M::kU, kY = M::kY, kH = M::kHidden;
  static_assert(kHorizon >= 1 && kAlphas >= 1, "horizon and step-size count >= 1");
  // Loss type: q15 int64 in Q(2 kFracY + kFracLossW); f32 float.
  using Loss = std::conditional_t<N::kFixed, std::int64_t, float>;

  // What the predictions are compared with.
  //  kAbsolute (the paper): e_k = y_est,k - y_ref.
  //  kRelativeToHold: e_k = y_est,k - (y_ref + y_hold,k - y_t), where y_hold
  //    is the model's prediction for holding the command (u = 0) and y_t the
  //    measurement now. Only the commands' predicted *effect* y_est - y_hold
  //    enters, plus the deviation measured now, y_t - y_ref: a bias of the
  //    model's absolute predictions (a stale PB, a state it never saw)
  //    cancels instead of being "corrected" by the commands (offset-free
  //    predictive control). One more rollout per period.
  enum class Reference : std::uint8_t { kAbsolute = 0, kRelativeToHold = 1 };

  // Run-time settings (defaults from the generated model). Changing them
  // never changes a buffer size.
  struct Settings {
    int epochs = M::kControlEpochs;         // N_epoch (0: only the warm start)
    int truncation = M::kControlTruncation;  // K >= 1; >= horizon: full BPTT
    Reference reference = Reference::kRelativeToHold;
    // true: a step is taken only if some step size lowers L (a monotone line
    // search); false: the best step size is adopted even if L rises (the
    // paper's rule).
    bool keep_if_no_descent = true;
    // Commands the stabiliser may change (others stay at the hold command);
    // from the generated model (codegen --control-commands).
    bool active[kU] = {};
    Settings() noexcept {
      for (int i = 0; i < kU; ++i) active[i] = M::kControlActive[i];
    }
  };

  // Forgets the plan: the next warm start is `hold` at every step
  // (standardised Q(kFracIn), e.g. the command "no change"); lag inputs'
  // history is `hold` too until set_lag_history.
  void reset(const Value (&hold)[kU]) noexcept {
    set_hold(hold);
    for (int k = 0; k < kHorizon; ++k)
      for (int i = 0; i < kU; ++i) seq_[k][i] = hold[i];
    if constexpr (kHasLags) {
      for (int i = 0; i < kU; ++i)
        for (int k = 0; k < kMaxLag; ++k) lag_history_[i][k] = hold[i];
    }
  }
  void set_reference(const Value (&y_ref)[kY]) noexcept {
    for (int i = 0; i < kY; ++i) y_ref_[i] = y_ref[i];
  }
  // The hold command (standardised "no change"), used by kRelativeToHold.
  void set_hold(const Value (&hold)[kU]) noexcept {
    for (int i = 0; i < kU; ++i) hold_[i] = hold[i];
  }
  // Holds input i (one the stabiliser does not set, e.g. a derived input) at
  // `value` (standardised Q(kFracIn)) in the hold command and at every step
  // of the plan: over the horizon it stays where it is now.
  void hold_input(int i, Value value) noexcept {
    hold_[i] = value;
    for (int k = 0; k < kHorizon; ++k) seq_[k][i] = value;
  }
  // The value lag input i (kLag, lag d) takes at horizon step k < d: its
  // base command already applied, u_b,t+k-d, in slot i's standardisation
  // (Q(kFracIn)). Steps k >= d take the plan's own commands.
  void set_lag_history(int i, int k, Value value) noexcept {
    if constexpr (kHasLags) {
      if (i >= 0 && i < kU && k >= 0 && k < kMaxLag) lag_history_[i][k] = value;
    }
  }
  Settings& settings() noexcept { return settings_; }

  // Optimises the sequence from the standardised initial state x_t (and the
  // measurement y_t it was built from, Q(kFracY)) under PB p and writes its
  // first command to `command` (Q(kFracIn)); then shifts the sequence for
  // the next period's warm start.
  void plan(HadynetNet<M>& net, const Value (&x)[M::kX], const Value (&y_now)[kY],
            const Value (&pb)[M::kPb], Value (&command)[kU]) noexcept {
    t_ = &net.tensors();  // step sizes, loss weights and standardisation of the net's model
    if constexpr (kHasLags) set_lag_maps();
    net.encode(x, pb);
    net.save(start_);
    set_step_references(net, y_now);
    // trace_[best_slot_] always holds the rollout of seq_.
    loss_initial_ = rollout(net, seq_, best_slot_);
    Loss loss = loss_initial_;
    gradient_valid_ = false;
    best_alpha_ = -1;
    for (int epoch = 0; epoch < settings_.epochs; ++epoch) {
      if (!gradient(net)) break;  // zero gradient: already optimal
      if (epoch == 0) {
        for (int k = 0; k < kHorizon; ++k)
          for (int i = 0; i < kU; ++i) first_direction_[k][i] = unit_[k][i];
        gradient_valid_ = true;
      }
      // Try every step size into the other slot; the best candidate of the
      // batch is adopted (as in the paper) and its slot becomes best_slot_.
      bool have_best = settings_.keep_if_no_descent;
      Loss best = loss;
      Value best_seq[kHorizon][kU] = {};
      copy(seq_, best_seq);
      for (int a = 0; a < kAlphas; ++a) {
        Value cand[kHorizon][kU];
        step_along(t_->control_alpha[a], cand);
        const Loss l = rollout(net, cand, 1 - best_slot_);
        if (!have_best || l < best) {
          have_best = true;
          best = l;
          best_alpha_ = a;
          copy(cand, best_seq);
          best_slot_ = 1 - best_slot_;
        }
      }
      copy(best_seq, seq_);
      loss = best;
      if (best_alpha_ < 0) break;  // no step size lowers L: keep the sequence
    }
    loss_final_ = loss;
    // The first step's inputs: the command, and the derived inputs as used.
    input_at([this](int j) -> const Value(&)[kU] { return seq_[j]; }, 0, command);
    // Warm start of the next period: shift by one, repeat the last entry.
    for (int k = 0; k + 1 < kHorizon; ++k)
      for (int i = 0; i < kU; ++i) seq_[k][i] = seq_[k + 1][i];
  }

  // A loss as a real number (q15: Q(2 kFracY + kFracLossW) -> real).
  static float loss_value(Loss l) noexcept {
    if constexpr (N::kFixed) {
      return static_cast<float>(l) / static_cast<float>(std::int64_t{1} << (2 * M::kFracY + M::kFracLossW));
    } else {
      return l;
    }
  }

  // The rollout traces are scratch of one plan() call: between calls another
  // user may borrow them (the runtime lends them to PB adaptation, which
  // never runs in the same period), kScratchTraces entries.
  static constexpr int kScratchTraces = 2 * kHorizon;
  StepTrace<M>* scratch_traces() noexcept { return trace_[0]; }

  // Diagnostics of the last plan().
  Loss loss_initial() const noexcept { return loss_initial_; }  // warm start's L
  Loss loss_final() const noexcept { return loss_final_; }      // adopted sequence's L
  int best_alpha() const noexcept { return best_alpha_; }        // index into kControlAlpha
  // g/|g| of the first epoch (real values; valid if gradient_valid()).
  bool gradient_valid() const noexcept { return gradient_valid_; }
  float first_direction(int step, int channel) const noexcept {
    if constexpr (N::kFixed) {
      return static_cast<float>(first_direction_[step][channel]) / 32768.0f;
    } else {
      return first_direction_[step][channel];
    }
  }
  // The loss of a predicted sequence against the reference (also used by
  // tests and the replay for E = the force part).
  Loss loss(const Value (&y_est)[kHorizon][kY]) const noexcept {
    Loss l = 0;
    for (int k = 0; k < kHorizon; ++k) l += loss_step(y_est[k], ref_[k]);
    return l;
  }

 private:
  using UnitT = std::conditional_t<N::kFixed, std::int32_t, float>;  // Q15 in int32 / float

  using Row = Value[kU];
  static constexpr int kMaxLag = longest_command_lag<M>();
  static constexpr bool kHasLags = [] {
    for (int i = 0; i < kU; ++i)
      if (M::kUDerived[i] == DerivedKind::kLag) return true;
    return false;
  }();
  static_assert(command_lags_valid<M>(), "kUDerivedLag: 1..kMaxDerivedLag for a kLag input, 0 for every other");
  // Scale of the map from a base command's standardisation to its lag
  // slot's: q15 Q(kLagScaleFrac) in int32; f32 float.
  static constexpr int kLagScaleFrac = 16;
  using LagScale = std::conditional_t<N::kFixed, std::int32_t, float>;

  // The lag maps of the current model: v_lag = scale v_base + offset, with
  // scale = std_b / std_lag and offset = (mean_b - mean_lag) / std_lag.
  void set_lag_maps() noexcept {
    for (int i = 0; i < kU; ++i) {
      if (M::kUDerived[i] != DerivedKind::kLag) continue;
      const int b = M::kUDerivedBase[i];
      const float scale = t_->u_std[b] * t_->u_inv_std[i];
      const float offset = (t_->u_mean[b] - t_->u_mean[i]) * t_->u_inv_std[i];
      if constexpr (N::kFixed) {
        lag_scale_[i] = fixed::real_to_fixed<std::int32_t, kLagScaleFrac>(scale);
      } else {
        lag_scale_[i] = scale;
      }
      lag_offset_[i] = N::template from_real<M::kFracIn>(offset);
    }
  }

  // The model's inputs at horizon step k, u (Q(kFracIn)), of the plan whose
  // step j is row(j): row(k), with each lag input replaced by its base
  // command d steps earlier (see the header).
  template <class Rows>
  void input_at(Rows row, int k, Value (&u)[kU]) const noexcept {
    const Row& r = row(k);
    for (int i = 0; i < kU; ++i) u[i] = r[i];
    if constexpr (kHasLags) {
      for (int i = 0; i < kU; ++i) {
        if (M::kUDerived[i] != DerivedKind::kLag) continue;
        const int d = M::kUDerivedLag[i];
        if (k < d) {
          u[i] = lag_history_[i][k];
          continue;
        }
        const Value base = row(k - d)[M::kUDerivedBase[i]];
        if constexpr (N::kFixed) {
          const std::int64_t scaled = fixed::rounding_shift_right(std::int64_t{lag_scale_[i]} * base, kLagScaleFrac);
          u[i] = fixed::saturate_i16(scaled + lag_offset_[i]);
        } else {
          u[i] = lag_scale_[i] * base + lag_offset_[i];
        }
      }
    }
  }

  // g_ of the lag inputs added to their base commands d steps earlier (the
  // chain rule through input_at), then zeroed: a lag input is never planned.
  void fold_lag_gradients() noexcept {
    for (int k = 0; k < kHorizon; ++k) {
      for (int i = 0; i < kU; ++i) {
        if (M::kUDerived[i] != DerivedKind::kLag) continue;
        const int d = M::kUDerivedLag[i];
        if (k >= d) {
          Grad& to = g_[k - d][M::kUDerivedBase[i]];
          if constexpr (N::kFixed) {
            const std::int64_t add = fixed::rounding_shift_right(std::int64_t{lag_scale_[i]} * g_[k][i], kLagScaleFrac);
            to = fixed::saturate_i32(std::int64_t{to} + add);
          } else {
            to += lag_scale_[i] * g_[k][i];
          }
        }
        g_[k][i] = 0;
      }
    }
  }

  static void copy(const Value (&from)[kHorizon][kU], Value (&to)[kHorizon][kU]) noexcept {
    for (int k = 0; k < kHorizon; ++k)
      for (int i = 0; i < kU; ++i) to[k][i] = from[k][i];
  }

  // The per-step references ref_[k] of this period (see Reference).
  void set_step_references(HadynetNet<M>& net, const Value (&y_now)[kY]) noexcept {
    if (settings_.reference == Reference::kAbsolute) {
      for (int k = 0; k < kHorizon; ++k)
        for (int i = 0; i < kY; ++i) ref_[k][i] = y_ref_[i];
      return;
    }
    Value y_hold[kY];
    net.restore(start_);
    for (int k = 0; k < kHorizon; ++k) {
      if constexpr (kHasLags) {
        Value u[kU];
        input_at([this](int) -> const Value(&)[kU] { return hold_; }, k, u);
        net.step(u, y_hold);
      } else {
        net.step(hold_, y_hold);
      }
      for (int i = 0; i < kY; ++i) {
        if constexpr (N::kFixed) {
          ref_[k][i] = fixed::saturate_i16(std::int32_t{y_ref_[i]} + y_hold[i] - y_now[i]);
        } else {
          ref_[k][i] = y_ref_[i] + y_hold[i] - y_now[i];
        }
      }
    }
  }

  Loss loss_step(const Value (&y)[kY], const Value (&ref)[kY]) const noexcept {
    Loss l = 0;
    for (int i = 0; i < kY; ++i) {
      const Value w = y[i] >= ref[i] ? t_->loss_weight_up[i] : t_->loss_weight_down[i];
      if constexpr (N::kFixed) {
        const std::int64_t e = std::int64_t{y[i]} - ref[i];
        l += e * e * w;  // Q(2 kFracY + kFracLossW); < 2^47 per term
      } else {
        const float e = y[i] - ref[i];
        l += w * e * e;
      }
    }
    return l;
  }

  // Runs the sequence from the saved initial state, tracing into `slot`.
  Loss rollout(HadynetNet<M>& net, const Value (&seq)[kHorizon][kU], int slot) noexcept {
    net.restore(start_);
    for (int k = 0; k < kHorizon; ++k) {
      if constexpr (kHasLags) {
        Value u[kU];
        input_at([&seq](int j) -> const Value(&)[kU] { return seq[j]; }, k, u);
        net.step(u, y_est_[slot][k], &trace_[slot][k]);
      } else {
        net.step(seq[k], y_est_[slot][k], &trace_[slot][k]);
      }
    }
    return loss(y_est_[slot]);
  }

  // g = dL/du_seq of the sequence traced in the best slot; writes g/|g| to
  // unit_. Returns false if g == 0.
  bool gradient(HadynetNet<M>& net) noexcept {
    const int slot = best_slot_;
    // dL/dy = 2 w (y - y_ref); the factor 2 and (q15) a power of two that
    // brings the largest entry to 2^kGradFracBits are dropped (direction only).
    if constexpr (N::kFixed) {
      std::int64_t raw[kHorizon][kY];
      std::int64_t max_abs = 0;
      for (int k = 0; k < kHorizon; ++k) {
        for (int i = 0; i < kY; ++i) {
          const Value y = y_est_[slot][k][i];
          const std::int64_t w = y >= ref_[k][i] ? t_->loss_weight_up[i] : t_->loss_weight_down[i];
          raw[k][i] = w * (std::int64_t{y} - ref_[k][i]);
          const std::int64_t a = raw[k][i] < 0 ? -raw[k][i] : raw[k][i];
          if (a > max_abs) max_abs = a;
        }
      }
      if (max_abs == 0) return false;
      const int shift = grad_scale_shift(max_abs);  // max -> [2^20, 2^21)
      for (int k = 0; k < kHorizon; ++k)
        for (int i = 0; i < kY; ++i) dy_[k][i] = grad_scaled(raw[k][i], shift);
    } else {
      bool any = false;
      for (int k = 0; k < kHorizon; ++k) {
        for (int i = 0; i < kY; ++i) {
          const float y = y_est_[slot][k][i];
          const float w = y >= ref_[k][i] ? t_->loss_weight_up[i] : t_->loss_weight_down[i];
          dy_[k][i] = 2.0f * w * (y - ref_[k][i]);
          any = any || dy_[k][i] != 0.0f;
        }
      }
      if (!any) return false;
    }
    backward(net, slot);
    if constexpr (kHasLags) fold_lag_gradients();
    return normalise();
  }

  // g_[k] = dL/du_k over the traced rollout in `slot`.
  void backward(HadynetNet<M>& net, int slot) noexcept {
    for (int k = 0; k < kHorizon; ++k)
      for (int i = 0; i < kU; ++i) g_[k][i] = 0;
    const int depth = settings_.truncation < 1 ? 1 : settings_.truncation;
    if (depth >= kHorizon) {
      // Full BPTT: one backward sweep; dh, dc carry every later output.
      for (int j = 0; j < kH; ++j) dh_[j] = dc_[j] = 0;
      for (int k = kHorizon - 1; k >= 0; --k) {
        net.backward_decoder(dy_[k], dh_);
        net.backward_step(trace_[slot][k], dh_, dc_, g_[k], k > 0 ? dh_prev_ : nullptr);
        for (int j = 0; j < kH; ++j) dh_[j] = dh_prev_[j];
      }
      return;
    }
    // Truncated: output k's gradient flows back through steps k .. k-K+1.
    for (int k = kHorizon - 1; k >= 0; --k) {
      for (int j = 0; j < kH; ++j) dh_[j] = dc_[j] = 0;
      net.backward_decoder(dy_[k], dh_);
      const int last = k - depth + 1 > 0 ? k - depth + 1 : 0;
      for (int s = k; s >= last; --s) {
        net.backward_step(trace_[slot][s], dh_, dc_, g_[s], s > last ? dh_prev_ : nullptr);
        for (int j = 0; j < kH; ++j) dh_[j] = dh_prev_[j];
      }
    }
  }

  // unit_ = g / |g|. Returns false if g == 0.
  bool normalise() noexcept {
    for (int k = 0; k < kHorizon; ++k)
      for (int i = 0; i < kU; ++i)
        if (!settings_.active[i]) g_[k][i] = 0;
    if constexpr (N::kFixed) {
      std::int64_t max_abs = 0;
      for (int k = 0; k < kHorizon; ++k) {
        for (int i = 0; i < kU; ++i) {
          const std::int64_t a = g_[k][i] < 0 ? -std::int64_t{g_[k][i]} : g_[k][i];
          if (a > max_abs) max_abs = a;
        }
      }
      if (max_abs == 0) return false;
      // Bring the largest entry to [2^23, 2^24): squares < 2^48, and the sum
      // of kHorizon * kU of them stays far below 2^63.
      static_assert(kHorizon * kU < (1 << 14), "sum of squares must fit in int64");
      const int shift = bit_length(max_abs) - 24;
      std::int64_t scaled[kHorizon][kU];
      std::uint64_t sum_sq = 0;
      for (int k = 0; k < kHorizon; ++k) {
        for (int i = 0; i < kU; ++i) {
          const std::int64_t v = shift >= 0 ? fixed::rounding_shift_right(g_[k][i], shift)
                                            : std::int64_t{g_[k][i]} * (std::int64_t{1} << -shift);
          scaled[k][i] = v;
          sum_sq += static_cast<std::uint64_t>(v * v);
        }
      }
      const std::int64_t norm = fixed::isqrt_round_u64(sum_sq);  // >= 2^23
      for (int k = 0; k < kHorizon; ++k) {
        for (int i = 0; i < kU; ++i) {
          // round(v * 2^15 / norm), half away from zero; |result| <= 2^15.
          const std::int64_t num = scaled[k][i] * (std::int64_t{1} << 15);
          const std::int64_t q = (num >= 0 ? num + norm / 2 : num - norm / 2) / norm;
          unit_[k][i] = static_cast<std::int32_t>(q);
        }
      }
      return true;
    } else {
      float sum_sq = 0.0f;
      for (int k = 0; k < kHorizon; ++k)
        for (int i = 0; i < kU; ++i) sum_sq += g_[k][i] * g_[k][i];
      if (!(sum_sq > 0.0f)) return false;
      const float norm = std::sqrt(sum_sq);
      for (int k = 0; k < kHorizon; ++k)
        for (int i = 0; i < kU; ++i) unit_[k][i] = g_[k][i] / norm;
      return true;
    }
  }

  // cand = seq_ - alpha * unit_ (alpha Q(kFracIn)), rounded and saturated.
  void step_along(Value alpha, Value (&cand)[kHorizon][kU]) const noexcept {
    for (int k = 0; k < kHorizon; ++k) {
      for (int i = 0; i < kU; ++i) {
        if constexpr (N::kFixed) {
          const std::int64_t step = fixed::rounding_shift_right(std::int64_t{alpha} * unit_[k][i], 15);
          cand[k][i] = fixed::saturate_i16(std::int64_t{seq_[k][i]} - step);
        } else {
          cand[k][i] = seq_[k][i] - alpha * unit_[k][i];
        }
      }
    }
  }

  Settings settings_{};
  Value seq_[kHorizon][kU] = {};
  Value y_ref_[kY] = {};
  Value hold_[kU] = {};
  // Per lag input (sized 1 in a model without any): its value at steps
  // k < d, and the map from its base's standardisation.
  static constexpr int kLagSlots = kHasLags ? kU : 1;
  Value lag_history_[kLagSlots][kMaxLag] = {};
  LagScale lag_scale_[kLagSlots] = {};
  Value lag_offset_[kLagSlots] = {};
  Value ref_[kHorizon][kY] = {};  // per-step reference of this period
  typename HadynetNet<M>::State start_{};
  const ModelTensors<M>* t_ = &kCompiledTensors<M>;  // the model of the last plan()'s net
  StepTrace<M> trace_[2][kHorizon] = {};
  Value y_est_[2][kHorizon][kY] = {};
  int best_slot_ = 0;
  Grad dy_[kHorizon][kY] = {};
  Grad dh_[kH] = {};
  Grad dh_prev_[kH] = {};
  Grad dc_[kH] = {};
  Grad g_[kHorizon][kU] = {};
  UnitT unit_[kHorizon][kU] = {};
  UnitT first_direction_[kHorizon][kU] = {};
  Loss loss_initial_ = 0;
  Loss loss_final_ = 0;
  int best_alpha_ = -1;
  bool gradient_valid_ = false;
};

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_GRASP_STABILIZER_H_
