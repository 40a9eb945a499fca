// On-device PB adaptation (seed paper III-D, "online"; docs/firmware.md,
// "Adapting the PB on the device"): the firmware re-fits the parametric bias
// alone to the frames it sees, with the network's weights frozen, and
// recognises the grasped object as the nearest PB of the model's PB table.
//
// What it computes. The newest frames (a ring sized at compile time:
// windows overlap, so frames are kept, not windows) give the windows of the
// trainer (window_dataset.h): window a is x from frames a, a+1, the commands
// of frames a+2 .. a+N+1 (each frame carries the command applied before it)
// and the targets y of the same frames, N = kTrainSteps. Its loss is the
// trainer's, L = mean over windows, steps and channels of (y_est - y)^2; the
// gradient dL/dp is back-propagated through time over the N steps (the PB
// enters every LSTM step and the encoder), and MomentumSGD
// (v = momentum v - lr g, p += v; Chainer's) moves the PB.
//
// Schedule, and where it departs from the paper's online rule (start once
// 100 windows are held, newest 200, 3 full-batch epochs per new window; the
// trainer's OnlinePbAdapter). One full-batch epoch over 200 windows is
// ~1.5 million multiply-accumulates per window here, far more than one 0.2 s
// period of a 168 MHz Cortex-M4 holds, so an epoch is spread over periods:
//  * an epoch starts from a snapshot of the newest (at most kMaxWindows)
//    windows, once at least Settings::start_windows are held;
//  * each period (work()) runs Settings::windows_per_period of them, oldest
//    first, summing the loss and the PB gradient; the frames they need are
//    never overwritten before use (kRingFrames, below);
//  * when the snapshot is done, one MomentumSGD step is taken: one full-batch
//    step per epoch instead of three per new window, i.e. the gradient of
//    the same loss on data that is at most one epoch old.
// The step-size safeguard is the trainer's idea (undo a step that raised
// the loss, clear the momentum, halve the rate) on the device's schedule: a
// step is judged one epoch later, by the loss at the new PB against the loss
// at the previous accepted PB *on the windows both epochs saw* (per-window
// losses are kept for this), so new data that is harder to predict (a new
// object) never counts as a bad step. A rejected step is undone and retried
// from the accepted PB with its gradient at half the rate and no momentum
// (a function-value restart of the momentum, O'Donoghue and Candes 2015);
// every accepted step doubles the rate back towards Settings::lr.
//
// Numerics. q15: the forward pass is HadynetNet's; the loss is an exact
// int64 sum in Q(2 kFracY); each window's dL/dy is brought to
// [2^20, 2^21) as the stabiliser's (the window's scale is kept), its PB
// gradient is summed in int64 at Q(kGradAccFrac); the PB is kept at
// Q(kFracIn + 16) (int32) so that steps far below the PB's resolution
// accumulate, the momentum in int64 at the same scale; everything is
// integer, so host and MCU agree bit for bit. f32: the same in float.
// Nothing allocates; every buffer is a member sized at compile time.
#ifndef HADYNET_FIRMWARE_CORE_PB_ADAPTER_H_
#define HADYNET_FIRMWARE_CORE_PB_ADAPTER_H_

#include <cmath>
#include <cstdint>

#include "firmware/core/boundary.h"
#include "firmware/core/hadynet_net.h"
#include "firmware/core/isqrt.h"

namespace hadynet::firmware {

// The nearest PBs of the model's PB table to a PB (standardised units).
struct PbRecognition {
  bool valid = false;  // false: the model has no PB table
  int state = -1;      // nearest row of the PB table
  float distance = 0.0f;
  // The nearest row whose object (its state name up to the first '/') is
  // another one, and its distance (-1 / 0 if every row names one object).
  int other_state = -1;
  float other_distance = 0.0f;
};

// kMaxWindowsT: windows an epoch covers (the paper: 200). The default
// Settings need at least 8 (stride 8, budget 4); a smaller adapter (tests)
// sets its own.
template <GeneratedModel M, int kMaxWindowsT = 200>
class PbAdapter {
 public:
  using N = Numerics<M>;
  using Value = typename M::Value;
  using Grad = typename N::Grad;
  static constexpr bool kFixed = N::kFixed;
  static constexpr int kX = M::kX, kU = M::kU, kY = M::kY, kPb = M::kPb, kH = M::kHidden;
  static constexpr int kSteps = M::kTrainSteps;  // N_train
  static constexpr int kMaxWindows = kMaxWindowsT;
  // A window needs kSteps + 2 frames; the epoch's oldest window is run
  // first, and at least one window per period, so frames arriving during an
  // epoch only overwrite frames already used (one spare frame).
  static constexpr int kRingFrames = kMaxWindows + kSteps + 2;
  static_assert(kSteps >= 1 && kMaxWindows >= 1, "N_train >= 1 and at least one window");
  static_assert(kPb >= 1, "a model without a PB has nothing to adapt");

  // q15: sums of squared errors in Q(2 kFracY); f32 float.
  using Loss = std::conditional_t<kFixed, std::int64_t, float>;
  // q15: fraction bits of the PB gradient sums and of the kept PB.
  static constexpr int kGradAccFrac = 32;
  static constexpr int kMasterFrac = M::kFracIn + 16;
  static constexpr int kMaxHalvings = 30;  // as the trainer's safeguard
  // f32: the largest error a window counts (standardised units), q15's y range at kFracY = 9.
  static constexpr float kMaxError = 64.0f;

  struct Settings {
    int start_windows = 100;     // windows held before the first epoch (paper: N_thre^online)
    int windows_per_period = 4;  // windows run per work() call: the period's budget (docs/firmware.md)
    // An epoch runs every window_stride-th of the newest windows (those
    // whose first frame is a multiple of it): neighbouring windows share
    // all but one of their steps, so this keeps the frames and nearly the
    // loss of the full set at a fraction of the cost (more steps per second).
    int window_stride = 8;  // chosen on validation zeroings (docs/firmware.md)
    float lr = 1.0f;             // MomentumSGD rate (the trainer's default), 0 < lr < 16
    float momentum = 0.9f;       // 0 <= momentum < 1
  };
  static bool valid(const Settings& s) noexcept {
    return s.start_windows >= 1 && s.start_windows <= kMaxWindows && s.windows_per_period >= 1 &&
           s.windows_per_period <= kMaxWindows && s.window_stride >= 1 && s.window_stride <= kMaxWindows && s.lr > 0.0f && s.lr < 16.0f && s.momentum >= 0.0f &&
           s.momentum < 1.0f;
  }

  explicit PbAdapter(const ModelTensors<M>& tensors = kCompiledTensors<M>) noexcept : t_(&tensors) {}

  // Uses `tensors` (standardisation, PB table) from now on; forgets everything.
  void use_model(const ModelTensors<M>& tensors) noexcept {
    t_ = &tensors;
    const Value zero[kPb] = {};
    restart(zero);
    frames_ = 0;
    segment_first_ = 0;
  }

  // Settings for the next epochs; false (and nothing changed) if invalid.
  bool set_settings(const Settings& s) noexcept {
    if (!valid(s)) return false;
    settings_ = s;
    return true;
  }
  const Settings& settings() const noexcept { return settings_; }

  // Starts over from PB `start` (Q(kFracIn)): no momentum, no epoch in
  // progress, the full rate. The frames held are kept.
  void restart(const Value (&start)[kPb]) noexcept {
    for (int i = 0; i < kPb; ++i) {
      pb_[i] = start[i];
      if constexpr (kFixed) {
        master_[i] = static_cast<std::int32_t>(std::int32_t{start[i]} * 65536);
      } else {
        master_[i] = start[i];
      }
      velocity_[i] = 0;
    }
    in_epoch_ = false;
    have_base_ = false;
    halvings_ = 0;
    updates_ = 0;
    rejected_ = 0;
    last_loss_ = 0.0f;
  }

  // The next frame starts a new recording: no window spans the boundary.
  void begin_segment() noexcept { segment_first_ = frames_; }

  // One frame (the model's frame: physical y_t and the command u_{t-1}).
  void push(const float (&y)[kY], const float (&u_prev)[kU]) noexcept {
    const int s = slot(frames_);
    for (int i = 0; i < kY; ++i) y_[s][i] = y[i];
    Boundary<M>(*t_).u_to_model(u_prev, u_[s]);
    segment_of_[s] = segment_first_;
    ++frames_;
  }

  // Spends one period's budget on the current epoch (starting one if enough
  // windows are held). `net`'s state is overwritten; `traces` (kSteps
  // entries) is scratch of this call. True if the PB changed.
  bool work(HadynetNet<M>& net, StepTrace<M>* traces) noexcept {
    bool changed = false;
    for (int budget = settings_.windows_per_period; budget > 0;) {
      if (!in_epoch_ && !start_epoch()) break;
      if (!seek_valid()) {
        // No window (left) on the stride: an epoch that ran none ends the
        // period (a new snapshot would be the same until frames arrive).
        const bool ran = windows_run_ > 0;
        changed = finish_epoch() || changed;
        if (!ran) break;
        continue;
      }
      run_window(net, traces, next_++);
      --budget;
      if (!seek_valid()) changed = finish_epoch() || changed;
    }
    return changed;
  }

  const Value (&pb() const noexcept)[kPb] { return pb_; }
  int windows_held() const noexcept { return count_windows(nullptr); }
  std::uint32_t updates() const noexcept { return updates_; }    // steps taken (incl. retried ones)
  std::uint32_t rejected() const noexcept { return rejected_; }  // steps undone by the safeguard
  int halvings() const noexcept { return halvings_; }
  bool epoch_in_progress() const noexcept { return in_epoch_; }
  // Mean squared error (standardised units) of the last finished epoch, at the PB it ran with.
  float last_loss() const noexcept { return last_loss_; }
  // dL/dp of the last finished epoch (standardised units).
  void last_gradient(float (&g)[kPb]) const noexcept {
    for (int i = 0; i < kPb; ++i) {
      if constexpr (kFixed) {
        g[i] = static_cast<float>(static_cast<double>(last_grad_[i]) / static_cast<double>(std::int64_t{1} << kMasterFrac));
      } else {
        g[i] = last_grad_[i];
      }
    }
  }

  // The PB table's nearest rows to the adapted PB.
  PbRecognition recognize() const noexcept { return recognize(pb_); }
  PbRecognition recognize(const Value (&pb)[kPb]) const noexcept {
    PbRecognition r;
    if constexpr (M::kStates < 1) {
      return r;
    } else {
      Loss best = 0, other = 0;
      for (int s = 0; s < M::kStates; ++s) {
        const Loss d2 = distance2(pb, t_->pb_table[s]);
        if (r.state < 0 || d2 < best) {
          r.state = s;
          best = d2;
        }
      }
      for (int s = 0; s < M::kStates; ++s) {
        if (same_object(t_->state_names[s], t_->state_names[r.state])) continue;
        const Loss d2 = distance2(pb, t_->pb_table[s]);
        if (r.other_state < 0 || d2 < other) {
          r.other_state = s;
          other = d2;
        }
      }
      r.valid = true;
      r.distance = distance(best);
      r.other_distance = r.other_state < 0 ? 0.0f : distance(other);
      return r;
    }
  }

 private:
  using Master = std::conditional_t<kFixed, std::int32_t, float>;  // PB at Q(kMasterFrac)
  using Wide = std::conditional_t<kFixed, std::int64_t, float>;    // gradients, momentum

  int slot(std::uint32_t frame) const noexcept { return static_cast<int>(frame % kRingFrames); }

  // Window a (its first frame) is complete, still in the ring and inside one segment.
  bool window_valid(std::uint32_t a) const noexcept {
    const std::uint32_t last = a + kSteps + 1;
    if (last >= frames_ || frames_ - a > kRingFrames) return false;
    return segment_of_[slot(last)] <= a;
  }

  // Counts the newest valid windows (at most kMaxWindows); writes the oldest counted to *first.
  int count_windows(std::uint32_t* first) const noexcept {
    if (frames_ < kSteps + 2) return 0;
    int n = 0;
    const std::uint32_t newest = frames_ - kSteps - 2;
    for (std::uint32_t a = newest;; --a) {
      if (frames_ - a > kRingFrames) break;
      if (window_valid(a)) {
        ++n;
        if (first != nullptr) *first = a;
        if (n == kMaxWindows) break;
      }
      if (a == 0) break;
    }
    return n;
  }

  bool start_epoch() noexcept {
    std::uint32_t first = 0;
    if (count_windows(&first) < settings_.start_windows) return false;
    in_epoch_ = true;
    ++epoch_;
    next_ = first;
    last_ = frames_ - kSteps - 2;
    windows_run_ = 0;
    loss_sum_ = 0;
    common_now_ = 0;
    common_base_ = 0;
    common_count_ = 0;
    for (int i = 0; i < kPb; ++i) grad_sum_[i] = 0;
    return true;
  }

  // Moves next_ to the next valid window of the epoch; false if none is left.
  bool seek_valid() noexcept {
    const auto stride = static_cast<std::uint32_t>(settings_.window_stride);
    while (next_ <= last_ && (next_ % stride != 0 || !window_valid(next_))) ++next_;
    return next_ <= last_;
  }

  // Forward and back-propagation through time of window a under pb_:
  // adds its loss and dL/dp to the epoch's sums.
  void run_window(HadynetNet<M>& net, StepTrace<M>* trace, std::uint32_t a) noexcept {
    const Boundary<M> boundary(*t_);
    Value x[kX];
    boundary.x_from_frames(y_[slot(a + 1)], y_[slot(a)], x);
    net.encode(x, pb_);
    typename HadynetNet<M>::State h0;
    net.save(h0);
    Value y_est[kY];
    Loss window_loss = 0;
    [[maybe_unused]] std::int64_t max_abs = 0;
    for (int k = 0; k < kSteps; ++k) {
      const int f = slot(a + 2 + static_cast<std::uint32_t>(k));
      Value target[kY];
      boundary.y_to_model(y_[f], target);
      net.step(u_[f], y_est, &trace[k]);
      for (int i = 0; i < kY; ++i) {
        if constexpr (kFixed) {
          const std::int32_t e = std::int32_t{y_est[i]} - target[i];
          error_[k][i] = e;
          window_loss += std::int64_t{e} * e;
          const std::int64_t abs_e = e < 0 ? -std::int64_t{e} : e;
          if (abs_e > max_abs) max_abs = abs_e;
        } else {
          // As q15 saturates: an error beyond +-kMaxError standardised units
          // counts as that much; a non-finite one (a NaN or infinite frame) as none.
          float e = y_est[i] - target[i];
          e = e > kMaxError ? kMaxError : (e < -kMaxError ? -kMaxError : (e == e ? e : 0.0f));
          error_[k][i] = e;
          window_loss += e * e;
        }
      }
    }
    record_loss(a, window_loss);
    ++windows_run_;
    loss_sum_ += window_loss;

    // dL/dy = e (the factor 2 / (kY kSteps B) is applied at the update).
    int shift = 0;
    if constexpr (kFixed) {
      if (max_abs == 0) return;  // a perfect fit: no gradient
      shift = grad_scale_shift(max_abs);
    }
    Grad dy[kY], dh[kH] = {}, dc[kH] = {}, dh_prev[kH], dpb[kPb] = {};
    for (int k = kSteps - 1; k >= 0; --k) {
      for (int i = 0; i < kY; ++i) {
        if constexpr (kFixed) {
          dy[i] = grad_scaled(error_[k][i], shift);
        } else {
          dy[i] = error_[k][i];
        }
      }
      net.backward_decoder(dy, dh);
      net.backward_step_pb(trace[k], dh, dc, dpb, dh_prev);
      for (int j = 0; j < kH; ++j) dh[j] = dh_prev[j];
    }
    net.backward_encoder_pb(h0.h, dh, dpb);
    if constexpr (!kFixed) {
      // A window whose forward pass met non-finite inputs adds no gradient.
      for (int i = 0; i < kPb; ++i)
        if (!std::isfinite(dpb[i])) return;
    }
    for (int i = 0; i < kPb; ++i) {
      if constexpr (kFixed) {
        // dpb's raw value is its real value times 2^(kFracY - shift).
        const int to_acc = kGradAccFrac - M::kFracY + shift;
        grad_sum_[i] += to_acc >= 0 ? fixed::saturating_shift_left(dpb[i], to_acc)
                                    : fixed::rounding_shift_right(dpb[i], -to_acc);
      } else {
        grad_sum_[i] += dpb[i];
      }
    }
  }

  // Keeps window a's loss under this epoch's PB; adds the pair (this PB,
  // the accepted base PB) to the common sums if the base epoch saw a.
  void record_loss(std::uint32_t a, Loss loss) noexcept {
    const int s = slot(a);
    const WindowLoss& base = losses_[base_slot_][s];
    if (have_base_ && base.window == a && base.epoch == base_epoch_) {
      common_now_ += loss;
      common_base_ += base.loss;
      ++common_count_;
    }
    losses_[1 - base_slot_][s] = WindowLoss{a, epoch_, loss};
  }

  // The step at the end of an epoch (see the file comment). True if the PB changed.
  bool finish_epoch() noexcept {
    in_epoch_ = false;
    if (windows_run_ == 0) return false;
    const std::int64_t elements = std::int64_t{kY} * kSteps * windows_run_;
    if constexpr (kFixed) {
      last_loss_ = static_cast<float>(static_cast<double>(loss_sum_) / static_cast<double>(elements) /
                                      static_cast<double>(std::int64_t{1} << (2 * M::kFracY)));
    } else {
      last_loss_ = loss_sum_ / static_cast<float>(elements);
    }
    Wide g[kPb];  // dL/dp: q15 at Q(kMasterFrac), f32 real
    for (int i = 0; i < kPb; ++i) {
      if constexpr (kFixed) {
        const std::int64_t q32 = divide_round(2 * grad_sum_[i], elements);
        g[i] = clamp_wide(fixed::rounding_shift_right(q32, kGradAccFrac - kMasterFrac));
      } else {
        g[i] = 2.0f * grad_sum_[i] / static_cast<float>(elements);
      }
    }
    for (int i = 0; i < kPb; ++i) last_grad_[i] = g[i];
    const bool accept = !have_base_ || common_count_ == 0 || common_now_ <= common_base_;
    if (accept) {
      for (int i = 0; i < kPb; ++i) {
        base_master_[i] = master_[i];
        base_grad_[i] = g[i];
      }
      base_epoch_ = epoch_;
      base_slot_ = 1 - base_slot_;
      have_base_ = true;
      if (halvings_ > 0) --halvings_;
      for (int i = 0; i < kPb; ++i) velocity_[i] = momentum_times(velocity_[i]) - lr_times(g[i]);
    } else {
      ++rejected_;
      for (int i = 0; i < kPb; ++i) master_[i] = base_master_[i];
      if (halvings_ == kMaxHalvings) {  // no step keeps the loss down: stay
        for (int i = 0; i < kPb; ++i) velocity_[i] = 0;
        set_pb_from_master();
        return true;
      }
      ++halvings_;
      for (int i = 0; i < kPb; ++i) velocity_[i] = -lr_times(base_grad_[i]);
    }
    for (int i = 0; i < kPb; ++i) {
      if constexpr (kFixed) {
        velocity_[i] = clamp_wide(velocity_[i]);
        const std::int64_t limit = std::int64_t{32767} << 16;
        std::int64_t p = std::int64_t{master_[i]} + velocity_[i];
        p = p > limit ? limit : (p < -limit - 65536 ? -limit - 65536 : p);
        master_[i] = static_cast<std::int32_t>(p);
      } else {
        master_[i] += velocity_[i];
      }
    }
    ++updates_;
    set_pb_from_master();
    return true;
  }

  void set_pb_from_master() noexcept {
    for (int i = 0; i < kPb; ++i) {
      if constexpr (kFixed) {
        pb_[i] = fixed::saturate_i16(fixed::rounding_shift_right(master_[i], 16));
      } else {
        pb_[i] = master_[i];
      }
    }
  }

  // lr 2^-halvings g (q15: lr in Q16, rounded once).
  Wide lr_times(Wide g) const noexcept {
    if constexpr (kFixed) {
      const auto lr_q16 = static_cast<std::int64_t>(settings_.lr * 65536.0f + 0.5f);
      return clamp_wide(fixed::rounding_shift_right(lr_q16 * g, 16 + halvings_));
    } else {
      return std::ldexp(settings_.lr, -halvings_) * g;
    }
  }
  Wide momentum_times(Wide v) const noexcept {
    if constexpr (kFixed) {
      const auto m_q15 = static_cast<std::int64_t>(settings_.momentum * 32768.0f + 0.5f);
      return fixed::rounding_shift_right(m_q15 * v, 15);
    } else {
      return settings_.momentum * v;
    }
  }
  // q15 gradients and velocities stay within +-2^40 (a PB step of 2^15
  // standardised units), so products with the rate fit int64.
  static std::int64_t clamp_wide(std::int64_t v) noexcept {
    constexpr std::int64_t kLimit = std::int64_t{1} << 40;
    return v > kLimit ? kLimit : (v < -kLimit ? -kLimit : v);
  }
  static std::int64_t divide_round(std::int64_t num, std::int64_t den) noexcept {  // den > 0
    return (num >= 0 ? num + den / 2 : num - den / 2) / den;
  }

  static Loss distance2(const Value (&a)[kPb], const Value (&b)[kPb]) noexcept {
    Loss d2 = 0;
    for (int i = 0; i < kPb; ++i) {
      if constexpr (kFixed) {
        const std::int64_t d = std::int64_t{a[i]} - b[i];
        d2 += d * d;
      } else {
        const float d = a[i] - b[i];
        d2 += d * d;
      }
    }
    return d2;
  }
  static float distance(Loss d2) noexcept {
    if constexpr (kFixed) {
      return static_cast<float>(fixed::isqrt_round_u64(static_cast<std::uint64_t>(d2))) /
             static_cast<float>(1 << M::kFracIn);
    } else {
      return std::sqrt(d2);
    }
  }
  // The object of a state name is the part before the first '/' (the trainer
  // names states object/init/wear; a name without '/' is its own object).
  static bool same_object(const char (&a)[kStateNameBytes], const char (&b)[kStateNameBytes]) noexcept {
    for (int i = 0; i < kStateNameBytes; ++i) {
      const bool end_a = a[i] == '\0' || a[i] == '/', end_b = b[i] == '\0' || b[i] == '/';
      if (end_a || end_b) return end_a && end_b;
      if (a[i] != b[i]) return false;
    }
    return true;
  }

  struct WindowLoss {
    std::uint32_t window = 0;  // first frame of the window
    std::uint32_t epoch = 0;   // the epoch that ran it (0: none)
    Loss loss = 0;
  };

  const ModelTensors<M>* t_;
  Settings settings_{};
  // Frames by frame number modulo kRingFrames: y physical (the model's
  // frame; x's changes need it), the command standardised (as the net reads it).
  float y_[kRingFrames][kY] = {};
  Value u_[kRingFrames][kU] = {};
  std::uint32_t segment_of_[kRingFrames] = {};  // first frame of the frame's segment
  std::uint32_t frames_ = 0;                    // frames pushed so far
  std::uint32_t segment_first_ = 0;
  // The PB.
  Value pb_[kPb] = {};
  Master master_[kPb] = {};
  Wide velocity_[kPb] = {};
  int halvings_ = 0;
  std::uint32_t updates_ = 0;
  std::uint32_t rejected_ = 0;
  float last_loss_ = 0.0f;
  Wide last_grad_[kPb] = {};
  // The last accepted PB, its gradient and the epoch that measured them.
  bool have_base_ = false;
  Master base_master_[kPb] = {};
  Wide base_grad_[kPb] = {};
  std::uint32_t base_epoch_ = 0;
  int base_slot_ = 0;
  WindowLoss losses_[2][kRingFrames] = {};  // [base_slot_]: the base epoch's; the other: this one's
  // The epoch in progress.
  bool in_epoch_ = false;
  std::uint32_t epoch_ = 0;
  std::uint32_t next_ = 0, last_ = 0;  // windows next_ .. last_ remain
  int windows_run_ = 0;
  Loss loss_sum_ = 0;
  Loss common_now_ = 0, common_base_ = 0;
  int common_count_ = 0;
  Wide grad_sum_[kPb] = {};  // q15: Q(kGradAccFrac)
  // One window's errors (its traces are the caller's).
  std::conditional_t<kFixed, std::int32_t, float> error_[kSteps][kY] = {};
};

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_PB_ADAPTER_H_
