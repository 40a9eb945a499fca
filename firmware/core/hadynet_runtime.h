// The firmware's periodic job (every 0.2 s): one sensor frame in, one result
// out — HADYNET's estimate of the current y, the contact distance d and flag,
// and (in control mode) the grasp stabiliser's command. The active PB and the
// mode are set at run time (e.g. from the link). Same sources on host and MCU.
//
// Timing of one period t (log row t; docs/log-format.md):
//   in : y_t (measured now) and u_{t-1} (the command applied since t-1);
//   out: prediction = y_est_t from x_{t-N} and u_[t-N, t) under the active PB
//        (N = N_detect; valid from the (N+2)-th frame on), d and contact
//        (modes detect and control, if the model has detection statistics),
//        command = u_t from the stabiliser (mode control; needs 2 frames).
// Entering control mode takes the next frame's y as the reference y_ref.
// A model with a sensor model or derived inputs (sensor_stage.h) sees every
// frame in its own frame, and its prediction is reported as measured.
// PB adaptation (pb_adapter.h) runs beside the modes when switched on: every
// frame goes into its ring, and in observe and detect each period spends
// its budget on PB updates after the period's own work; in control it
// pauses (the stabiliser takes the period; frames are still kept). The
// result reports the adapted PB's nearest trained states (recognition);
// use_adapted_pb() makes it the active PB.
#ifndef HADYNET_FIRMWARE_CORE_HADYNET_RUNTIME_H_
#define HADYNET_FIRMWARE_CORE_HADYNET_RUNTIME_H_

#include <cstdint>

#include "firmware/core/boundary.h"
#include "firmware/core/detector.h"
#include "firmware/core/grasp_stabilizer.h"
#include "firmware/core/hadynet_net.h"
#include "firmware/core/pb_adapter.h"
#include "firmware/core/sensor_stage.h"

namespace hadynet::firmware {

enum class Mode : std::uint8_t {
  kObserve = 0,  // prediction only
  kDetect = 1,   // prediction, d, contact
  kControl = 2,  // as detect, plus the stabiliser's command
};

template <GeneratedModel M>
struct SensorFrame {
  float y[M::kY];       // y_t, physical (log units)
  float u_prev[M::kU];  // u_{t-1}, physical
};

template <GeneratedModel M>
struct StepResult {
  bool prediction_valid = false;
  float prediction[M::kY] = {};  // y_est_t, physical
  bool distance_valid = false;
  float d = 0.0f;  // Mahalanobis distance (standardised units)
  bool contact = false;
  bool command_valid = false;
  float command[M::kU] = {};  // u_t, physical
  // PB adaptation (when switched on): steps taken so far, and the nearest
  // trained states of the adapted PB (valid once a step has been taken).
  bool adapt_valid = false;
  std::uint32_t adapt_updates = 0;
  PbRecognition recognition;
};

template <GeneratedModel M>
class HadynetRuntime {
 public:
  using N = Numerics<M>;
  using Value = typename M::Value;
  using B = Boundary<M>;
  using Det = Detector<M>;

  // Runs the model `tensors` (the compiled-in model by default; a model
  // slot's payload after a model update, docs/model-update.md), which must
  // outlive the runtime.
  explicit HadynetRuntime(const ModelTensors<M>& tensors = kCompiledTensors<M>) noexcept
      : t_(&tensors), boundary_(tensors), sensor_(tensors), net_(tensors) {
    init_pb();
    reset();
  }
  const ModelTensors<M>& tensors() const noexcept { return *t_; }

  // Runs `tensors` from now on (e.g. the model a boot chose from a flash
  // slot): as a runtime constructed with them, except that the mode and the
  // control settings are kept. `tensors` must outlive the runtime.
  void use_model(const ModelTensors<M>& tensors) noexcept {
    t_ = &tensors;
    boundary_ = B(tensors);
    sensor_ = SensorStage<M>(tensors);
    net_ = HadynetNet<M>(tensors);
    adapter_.use_model(tensors);
    adapting_ = false;
    init_pb();
    reset();
  }

  // Clears the history and the plan; keeps the mode and the PB. The PB
  // starts as the detection PB (or PB table row 0, or zero).
  void reset() noexcept {
    history_.clear();
    sensor_.reset();
    reference_pending_ = true;
    adapter_.begin_segment();
    const float zero_u[M::kU] = {};
    boundary_.u_to_model(zero_u, hold_);
    stabilizer_.reset(hold_);
  }

  Mode mode() const noexcept { return mode_; }
  void set_mode(Mode mode) noexcept {
    if (mode == Mode::kControl && mode_ != Mode::kControl) {
      reference_pending_ = true;
      stabilizer_.reset(hold_);
    }
    mode_ = mode;
  }

  // Active PB from the PB table; false (and unchanged) if out of range.
  bool set_pb_state(int state) noexcept {
    if (state < 0 || state >= M::kStates) return false;
    for (int i = 0; i < M::kPb; ++i) pb_[i] = t_->pb_table[state][i];
    return true;
  }
  // Active PB from standardised real values (saturated into the format).
  void set_pb(const float (&pb)[M::kPb]) noexcept { B::real_to_in(pb, pb_); }
  const Value (&pb() const noexcept)[M::kPb] { return pb_; }

  // PB adaptation on (starting from the active PB, with the frames it
  // already holds) or off (the adapted PB is kept, frames are not).
  void set_adapting(bool on) noexcept {
    if (on && !adapting_) adapter_.restart(pb_);
    adapting_ = on;
  }
  bool adapting() const noexcept { return adapting_; }
  const PbAdapter<M>& adapter() const noexcept { return adapter_; }
  bool set_adapt_settings(const typename PbAdapter<M>::Settings& s) noexcept { return adapter_.set_settings(s); }
  // The adapted PB becomes the active PB (detection, control); adaptation
  // goes on from it.
  void use_adapted_pb() noexcept {
    for (int i = 0; i < M::kPb; ++i) pb_[i] = adapter_.pb()[i];
  }

  typename GraspStabilizer<M>::Settings& control_settings() noexcept {
    return stabilizer_.settings();
  }
  const GraspStabilizer<M>& stabilizer() const noexcept { return stabilizer_; }

  // One period. Never fails: results not yet computable are marked invalid.
  StepResult<M> step(const SensorFrame<M>& frame) noexcept {
    StepResult<M> out;
    float y_frame[M::kY], u_frame[M::kU];
    sensor_.to_model(frame.y, frame.u_prev, y_frame, u_frame);
    history_.push(y_frame, u_frame);
    Value y_now[M::kY];
    boundary_.y_to_model(y_frame, y_now);

    if (Det::ready(history_)) {
      Value y_est[M::kY];
      Det::estimate(history_, pb_, net_, y_est);
      sensor_.clip(y_est);
      float predicted[M::kY];
      boundary_.y_to_physical(y_est, predicted);
      sensor_.to_measured(predicted, out.prediction);
      out.prediction_valid = true;
      if (M::kHasDetection && mode_ != Mode::kObserve) {
        const auto d2 = Det::distance2(*t_, y_est, y_now);
        out.d = Det::distance(d2);
        out.contact = Det::is_contact(*t_, d2);
        out.distance_valid = true;
      }
    }

    if (mode_ == Mode::kControl) {
      if (reference_pending_) {
        stabilizer_.set_reference(y_now);
        reference_pending_ = false;
      }
      if (history_.count() >= 2) {
        Value x[M::kX];
        boundary_.x_from_frames(history_.y(0), history_.y(1), x);
        Value u[M::kU];
        if constexpr (SensorStage<M>::has_derived_inputs()) {
          // A lag input starts from the commands already applied (the plan's
          // own after d steps); the other derived inputs keep their value of
          // the newest frame over the horizon (grasp_stabilizer.h).
          boundary_.u_to_model(u_frame, u);
          for (int i = 0; i < M::kU; ++i) {
            if (M::kUDerived[i] == DerivedKind::kLag) {
              const int d = M::kUDerivedLag[i];
              for (int k = 0; k < d; ++k)
                stabilizer_.set_lag_history(i, k, boundary_.u_to_model(i, sensor_.past_command(i, d - k)));
            } else if (M::kUDerived[i] != DerivedKind::kNone) {
              stabilizer_.hold_input(i, u[i]);
            }
          }
        }
        stabilizer_.plan(net_, x, y_now, pb_, u);
        boundary_.u_to_physical(u, out.command);
        out.command_valid = true;
      }
    }

    if (adapting_) {
      adapter_.push(y_frame, u_frame);
      if (mode_ != Mode::kControl) adapter_.work(net_, adapt_traces());
      out.adapt_updates = adapter_.updates();
      out.adapt_valid = out.adapt_updates > 0;
      if (out.adapt_valid) out.recognition = adapter_.recognize();
    }
    return out;
  }

 private:
  void init_pb() noexcept {
    if constexpr (M::kHasDetection) {
      for (int i = 0; i < M::kPb; ++i) pb_[i] = t_->detect_pb[i];
    } else if constexpr (M::kStates > 0) {
      for (int i = 0; i < M::kPb; ++i) pb_[i] = t_->pb_table[0][i];
    }
  }

  // PB adaptation's back-propagation traces: the stabiliser's rollout
  // traces (scratch of plan(); adaptation never runs in control mode), or
  // its own if the stabiliser's horizon holds too few.
  static constexpr bool kBorrowTraces = GraspStabilizer<M>::kScratchTraces >= M::kTrainSteps;
  struct OwnTraces {
    StepTrace<M> t[M::kTrainSteps];
  };
  struct NoTraces {};
  StepTrace<M>* adapt_traces() noexcept {
    if constexpr (kBorrowTraces) {
      return stabilizer_.scratch_traces();
    } else {
      return own_traces_.t;
    }
  }

  const ModelTensors<M>* t_;
  B boundary_;
  Mode mode_ = Mode::kDetect;
  Value pb_[M::kPb] = {};
  Value hold_[M::kU] = {};
  bool reference_pending_ = true;
  SensorStage<M> sensor_;
  typename Det::History history_{};
  HadynetNet<M> net_;
  GraspStabilizer<M> stabilizer_{};
  bool adapting_ = false;
  PbAdapter<M> adapter_{*t_};
  [[no_unique_address]] std::conditional_t<kBorrowTraces, NoTraces, OwnTraces> own_traces_{};
};

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_HADYNET_RUNTIME_H_
