// The model's sensor model and derived inputs at the core's boundary
// (model_contract.h; trainer/sensor_model.h and trainer/derived_inputs.h are
// the trainer's side, `hadynet residual --fix` adds them). A model trained on
// logs as they are has none, and then every function here copies.
//
//   measured frame -> model frame (to_model):
//     derived commands: sign(u_base) and the hysteresis state (the sign of
//       the last non-zero u_base, kept here), or the same of u_base's change
//       from the previous frame (an absolute command; the previous value is
//       kept here), or u_base of kUDerivedLag frames earlier (input dead
//       time; the newest kMaxLag bases are kept here), overwriting the
//       frame's values;
//     drift: D_c = (D_c + |y_c| kSensorPeriod) / (1 + rate kSensorPeriod)
//       (load: the accumulated level, the reading less its bias) or
//       D_c += kSensorPeriod (time), then y1_c = y_c - rate D_c;
//     cross-talk: y2_c = y1_c - gain g_s^-1(y1_s) (the source after the
//       drift step, through its curve if it has one: the model frame's
//       source, which to_measured adds back);
//     curves: y'_c = g_c^-1(y2_c) (the identity without a curve).
//   model-frame prediction -> measured (to_measured):
//     y_c = clip(g_c(y'_c) + gain y'_s + rate D_c), D_c as of the newest frame.
// g_c and g_c^-1 are piecewise linear through the curve's knots, continued
// along the end segments, with the trainer's segment rule and arithmetic
// (trainer/sensor_model.cc, curve_reading and curve_level) in binary32.
// The trainer does the same (to_model_frame, the --fix evaluation). A sensor
// delay is not undone here (it needs future samples): the network gets the
// late measurement. Float operations only, each one IEEE binary32 operation
// in a fixed order (-ffp-contract=off), so host and MCU agree bit for bit.
#ifndef HADYNET_FIRMWARE_CORE_SENSOR_STAGE_H_
#define HADYNET_FIRMWARE_CORE_SENSOR_STAGE_H_

#include "firmware/core/model_contract.h"
#include "firmware/core/model_tensors.h"

namespace hadynet::firmware {

template <GeneratedModel M>
class SensorStage {
 public:
  using Value = typename M::Value;
  static constexpr int kY = M::kY, kU = M::kU;

  // With the sensor model values of `tensors` (the compiled-in model by
  // default), which must outlive the stage.
  explicit constexpr SensorStage(const ModelTensors<M>& tensors = kCompiledTensors<M>) noexcept : t_(&tensors) {}

  // Forgets the drift integrals and the hysteresis states (a new log starts).
  void reset() noexcept {
    for (float& d : driver_) d = 0.0f;
    for (float& h : hysteresis_) h = 0.0f;
    for (float& b : previous_base_) b = 0.0f;
    for (auto& ring : lag_ring_)
      for (float& b : ring) b = 0.0f;
    lag_slot_ = 0;
    frames_ = 0;
  }

  // A measured frame (y_t, u_{t-1}; physical) in the model's frame.
  void to_model(const float (&y)[kY], const float (&u_prev)[kU], float (&y_model)[kY],
                float (&u_model)[kU]) noexcept {
    for (int i = 0; i < kU; ++i) {
      const float base = u_prev[M::kUDerivedBase[i]];
      const float sign = sign_of(base);
      // The change from the previous frame's base, compared, not subtracted
      // (the trainer's double difference has the same sign). A frame carries
      // u_{t-1}: the first frame after reset() carries no command yet, and
      // the first command (the second frame) has no change, as the
      // trainer's row 0 of a log.
      const float change = frames_ < 2 ? 0.0f : sign_of_difference(base, previous_base_[i]);
      previous_base_[i] = base;
      switch (M::kUDerived[i]) {
        case DerivedKind::kNone: u_model[i] = u_prev[i]; break;
        case DerivedKind::kSign: u_model[i] = sign; break;
        case DerivedKind::kHysteresis:
          if (sign != 0.0f) hysteresis_[i] = sign;
          u_model[i] = hysteresis_[i];
          break;
        case DerivedKind::kChangeSign: u_model[i] = change; break;
        case DerivedKind::kChangeHysteresis:
          if (change != 0.0f) hysteresis_[i] = change;
          u_model[i] = hysteresis_[i];
          break;
        case DerivedKind::kLag:
          // The base kUDerivedLag frames ago (read before this frame's is
          // kept): 0 until a command that old exists, as the trainer's first rows.
          u_model[i] = lag_ring_[i][(lag_slot_ + kMaxLag - M::kUDerivedLag[i]) % kMaxLag];
          lag_ring_[i][lag_slot_] = frames_ == 0 ? 0.0f : base;
          break;
      }
    }
    lag_slot_ = (lag_slot_ + 1) % kMaxLag;
    if (frames_ < 2) ++frames_;
    float drifted[kY];
    for (int i = 0; i < kY; ++i) drifted[i] = y[i];
    for (int k = 0; k < M::kDriftCount; ++k) {
      const int c = M::kDriftChannel[k];
      const float magnitude = y[c] < 0.0f ? -y[c] : y[c];
      if (M::kDriftIsLoad[k])
        driver_[k] = (driver_[k] + magnitude * M::kSensorPeriod) / (1.0f + t_->drift_rate[k] * M::kSensorPeriod);
      else
        driver_[k] += M::kSensorPeriod;
      // The time driver is t dt with t counted from 0 at the first frame.
      drifted[c] -= t_->drift_rate[k] * drift_driver(k);
    }
    for (int i = 0; i < kY; ++i) y_model[i] = drifted[i];
    for (int k = 0; k < M::kCrosstalkCount; ++k) {
      const int s = M::kCrosstalkSource[k], j = curve_of(s);
      const float source = j < 0 ? drifted[s] : piecewise_linear(t_->curve_reading, t_->curve_level, j, drifted[s]);
      y_model[M::kCrosstalkTarget[k]] -= t_->crosstalk_gain[k] * source;
    }
    for (int j = 0; j < M::kCurveCount; ++j) {
      float& v = y_model[M::kCurveChannel[j]];
      v = piecewise_linear(t_->curve_reading, t_->curve_level, j, v);  // g^-1
    }
  }

  // A model-frame prediction (physical) as the sensors would report it.
  void to_measured(const float (&y_model)[kY], float (&y)[kY]) const noexcept {
    for (int i = 0; i < kY; ++i) y[i] = y_model[i];
    for (int j = 0; j < M::kCurveCount; ++j) {
      const int c = M::kCurveChannel[j];
      y[c] = piecewise_linear(t_->curve_level, t_->curve_reading, j, y_model[c]);  // g
    }
    for (int k = 0; k < M::kCrosstalkCount; ++k)
      y[M::kCrosstalkTarget[k]] += t_->crosstalk_gain[k] * y_model[M::kCrosstalkSource[k]];
    for (int k = 0; k < M::kDriftCount; ++k) y[M::kDriftChannel[k]] += t_->drift_rate[k] * drift_driver(k);
    for (int k = 0; k < M::kClipCount; ++k) {
      float& v = y[M::kClipChannel[k]];
      if (M::kClipSide[k] > 0 ? v > t_->clip_rail[k] : v < t_->clip_rail[k]) v = t_->clip_rail[k];
    }
  }

  // The clips on a standardised model-frame estimate (Q(kFracY)), so that
  // detection compares what a saturating sensor can show: at each clip's
  // frame rail (kClipRailModel; none on a cross-talk target or a drifting
  // channel, which to_measured clips).
  void clip(Value (&y)[kY]) const noexcept {
    for (int k = 0; k < M::kClipCount; ++k) {
      Value& v = y[M::kClipChannel[k]];
      if (M::kClipSide[k] > 0 ? v > t_->clip_rail_model[k] : v < t_->clip_rail_model[k]) v = t_->clip_rail_model[k];
    }
  }

  // The base command of kLag slot i (physical, model frame) after frame t
  // (which carries u_{t-1}) went through to_model: u_base,t-frames_ago, for
  // 1 <= frames_ago <= kMaxLag; 0 where no command that old exists (as in
  // to_model).
  float past_command(int i, int frames_ago) const noexcept {
    return lag_ring_[i][(lag_slot_ + kMaxLag - frames_ago) % kMaxLag];
  }

  // The curve of y channel c (index into the kCurve* arrays), -1 without one.
  static constexpr int curve_of(int c) noexcept {
    for (int j = 0; j < M::kCurveCount; ++j)
      if (M::kCurveChannel[j] == c) return j;
    return -1;
  }

  static constexpr bool has_derived_inputs() noexcept {
    for (int i = 0; i < kU; ++i)
      if (M::kUDerived[i] != DerivedKind::kNone) return true;
    return false;
  }

 private:
  // D_k as of the newest frame: the accumulated level (load), or (frames - 1) periods for time.
  float drift_driver(int k) const noexcept {
    return M::kDriftIsLoad[k] ? driver_[k] : driver_[k] - M::kSensorPeriod;
  }

  // Curve j's piecewise-linear map through (from[k], to[k]) of its knots
  // (model_tensors.h), continued along the end segments: the segment is the
  // first whose upper knot is >= v (the last one beyond it), as the trainer's.
  using CurveValues = float[ModelTensors<M>::kCurveValues];
  static float piecewise_linear(const CurveValues& from, const CurveValues& to, int j, float v) noexcept {
    const int base = j * M::kCurveKnots;
    int k = base + 1;  // segment [k - 1, k]
    while (k + 1 < base + M::kCurveKnots && v > from[k]) ++k;
    return to[k - 1] + (v - from[k - 1]) * (to[k] - to[k - 1]) / (from[k] - from[k - 1]);
  }

  static constexpr float sign_of(float v) noexcept { return v > 0.0f ? 1.0f : (v < 0.0f ? -1.0f : 0.0f); }
  static constexpr float sign_of_difference(float a, float b) noexcept {
    return a > b ? 1.0f : (a < b ? -1.0f : 0.0f);
  }

  static constexpr int kDrifts = M::kDriftCount > 0 ? M::kDriftCount : 1;
  static_assert(curves_valid<M>(), "kCurve*: >= 2 knots, distinct y channels, strictly increasing knots");
  static constexpr int kMaxLag = longest_command_lag<M>();
  static_assert(command_lags_valid<M>(), "kUDerivedLag: 1..kMaxDerivedLag for a kLag input, 0 for every other");
  const ModelTensors<M>* t_;
  float driver_[kDrifts] = {};
  float hysteresis_[kU] = {};
  float previous_base_[kU] = {};  // per u slot: its base command in the previous frame
  // Per kLag u slot: its base command in the newest kMaxLag frames, the
  // newest at lag_slot_ - 1 (mod kMaxLag); unused for the other slots.
  float lag_ring_[kU][kMaxLag] = {};
  int lag_slot_ = 0;              // where this frame's base goes
  int frames_ = 0;                // frames since reset(), counted up to 2
};

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_SENSOR_STAGE_H_
