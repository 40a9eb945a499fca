// The data of a generated model that a model update may replace: weights
// (in the storage order the build's kernels read), standardisation, the PB
// table, detection statistics, control step sizes and loss weights, the
// sensor model's values (gains, rates, rails, curve knots). Everything else
// of the model contract (dimensions, formats, channel layout, counts, control
// constants) is its SHAPE: compile time, the same for every image this
// firmware accepts (shape_id below).
//
// The core reads the model through a `const ModelTensors<M>&`: the
// compiled-in one (kCompiledTensors<M>, the factory default, built at
// compile time from M's arrays) or one in a flash slot (firmware/model_update,
// docs/model-update.md), read in place. The host writes a slot's payload as
// the bytes of a ModelTensors<M> filled by build_tensors<M> from the new
// model's row-major arrays: the same code on both sides.
//
// Layout. The members are ordered by decreasing alignment (8, 4, 2, 1 bytes),
// so a ModelTensors has no padding between members on any ABI whose
// alignment of each type is its size (x86-64 and AAPCS agree): its bytes
// are the same on the PC and on the Cortex-M4 (checked below at compile
// time for every model on both). Its size is the image's payload length.
#ifndef HADYNET_FIRMWARE_CORE_MODEL_TENSORS_H_
#define HADYNET_FIRMWARE_CORE_MODEL_TENSORS_H_

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "firmware/core/kernels/dot_q15.h"
#include "firmware/core/model_contract.h"

namespace hadynet::firmware {

// The network's matrices. q15: packed for the forward kernel
// (kernels/dot_q15.h), one copy each: every W^T g of the backward passes is
// computed from the packed copies (kernels::dot_cols_packed_q15). f32:
// row-major as generated.
template <GeneratedModel M, bool kFixed = (M::kNumeric == Numeric::kQ15)>
struct NetworkWeights;

template <GeneratedModel M>
struct NetworkWeights<M, true> {
  static constexpr int kGates = 4 * M::kHidden;
  kernels::PackedMatrix<M::kHidden, M::kX + M::kPb> enc;  // [W_enc | x ; p], BN folded
  kernels::PackedMatrix<kGates, M::kU + M::kPb> ih;       // W_ih, input [u ; p]
  kernels::PackedMatrix<kGates, M::kHidden> hh;           // W_hh
  kernels::PackedMatrix<M::kY, M::kHidden> dec;           // W_dec
};

template <GeneratedModel M>
struct NetworkWeights<M, false> {
  static constexpr int kGates = 4 * M::kHidden;
  float enc[M::kHidden][M::kX + M::kPb];
  float ih[kGates][M::kU + M::kPb];
  float hh[kGates][M::kHidden];
  float dec[M::kY][M::kHidden];
};

// Bytes of a state name in the payload (NUL-padded; longer names are cut).
inline constexpr int kStateNameBytes = 32;

template <GeneratedModel M>
struct ModelTensors {
  using Value = typename M::Value;
  using Bias = typename M::Bias;
  using ThresholdSq = std::remove_cv_t<decltype(M::kDetectThresholdSq)>;  // q15 int64, f32 float
  static constexpr int kGates = 4 * M::kHidden;
  static constexpr int kPbRows = M::kStates > 0 ? M::kStates : 1;
  static constexpr int kCrosstalks = M::kCrosstalkCount > 0 ? M::kCrosstalkCount : 1;
  static constexpr int kDrifts = M::kDriftCount > 0 ? M::kDriftCount : 1;
  static constexpr int kClips = M::kClipCount > 0 ? M::kClipCount : 1;
  static constexpr int kCurveValues = (M::kCurveCount > 0 ? M::kCurveCount : 1) * M::kCurveKnots;

  // ---- 8 bytes
  std::uint64_t model_hash;  // FNV-1a 64 of the model file these tensors came from (kModelHash)
  // ---- 8 bytes (q15) or 4 (f32)
  ThresholdSq detect_threshold_sq;  // C_detect^2 (model_contract.h)
  // ---- float32, physical units (model_contract.h)
  float x_mean[M::kX], x_inv_std[M::kX];
  float u_mean[M::kU], u_std[M::kU], u_inv_std[M::kU];
  float y_mean[M::kY], y_std[M::kY], y_inv_std[M::kY];
  float detect_threshold;
  float crosstalk_gain[kCrosstalks];
  float drift_rate[kDrifts];
  float clip_rail[kClips];
  float curve_level[kCurveValues];    // knot k of curve j at [j * kCurveKnots + k] (model_contract.h)
  float curve_reading[kCurveValues];
  // ---- Bias (int32 in its accumulator's format, or float)
  Bias enc_bias[M::kHidden];
  Bias lstm_bias[kGates];
  Bias dec_bias[M::kY];
  // ---- Value (int16 or float)
  NetworkWeights<M> weights;
  Value pb_table[kPbRows][M::kPb];
  Value detect_pb[M::kPb];
  Value detect_mean[M::kY];
  Value detect_whiten[M::kY][M::kY];
  Value control_alpha[M::kControlAlphaCount];
  Value loss_weight_up[M::kY];
  Value loss_weight_down[M::kY];
  Value clip_rail_model[kClips];
  // ---- bytes
  char state_names[kPbRows][kStateNameBytes];
};

// The row-major arrays build_tensors reads, under the generated header's
// names: M itself (its static members) or a host object with the same
// members (the image writer's RowMajorModel, host-sim/model_image/row_major_model.h).
// Counts and shapes are M's.
template <GeneratedModel M, class Source>
constexpr void build_tensors(const Source& s, ModelTensors<M>& t) noexcept {
  t.model_hash = s.kModelHash;
  t.detect_threshold_sq = s.kDetectThresholdSq;
  for (int i = 0; i < M::kX; ++i) {
    t.x_mean[i] = s.kXMean[i];
    t.x_inv_std[i] = s.kXInvStd[i];
  }
  for (int i = 0; i < M::kU; ++i) {
    t.u_mean[i] = s.kUMean[i];
    t.u_std[i] = s.kUStd[i];
    t.u_inv_std[i] = s.kUInvStd[i];
  }
  for (int i = 0; i < M::kY; ++i) {
    t.y_mean[i] = s.kYMean[i];
    t.y_std[i] = s.kYStd[i];
    t.y_inv_std[i] = s.kYInvStd[i];
    t.dec_bias[i] = s.kDecBias[i];
    t.detect_mean[i] = s.kDetectMean[i];
    t.loss_weight_up[i] = s.kLossWeightUp[i];
    t.loss_weight_down[i] = s.kLossWeightDown[i];
    for (int j = 0; j < M::kY; ++j) t.detect_whiten[i][j] = s.kDetectWhiten[i][j];
  }
  t.detect_threshold = s.kDetectThreshold;
  for (int k = 0; k < ModelTensors<M>::kCrosstalks; ++k) t.crosstalk_gain[k] = s.kCrosstalkGain[k];
  for (int k = 0; k < ModelTensors<M>::kDrifts; ++k) t.drift_rate[k] = s.kDriftRate[k];
  for (int k = 0; k < ModelTensors<M>::kClips; ++k) {
    t.clip_rail[k] = s.kClipRail[k];
    t.clip_rail_model[k] = s.kClipRailModel[k];
  }
  for (int k = 0; k < ModelTensors<M>::kCurveValues; ++k) {
    t.curve_level[k] = s.kCurveLevel[k];
    t.curve_reading[k] = s.kCurveReading[k];
  }
  for (int r = 0; r < M::kHidden; ++r) t.enc_bias[r] = s.kEncBias[r];
  for (int r = 0; r < ModelTensors<M>::kGates; ++r) t.lstm_bias[r] = s.kLstmBias[r];
  if constexpr (M::kNumeric == Numeric::kQ15) {
    t.weights.enc = kernels::pack_matrix(s.kEncWeight);
    t.weights.ih = kernels::pack_matrix(s.kLstmWeightIh);
    t.weights.hh = kernels::pack_matrix(s.kLstmWeightHh);
    t.weights.dec = kernels::pack_matrix(s.kDecWeight);
  } else {
    for (int r = 0; r < M::kHidden; ++r)
      for (int c = 0; c < M::kX + M::kPb; ++c) t.weights.enc[r][c] = s.kEncWeight[r][c];
    for (int r = 0; r < ModelTensors<M>::kGates; ++r) {
      for (int c = 0; c < M::kU + M::kPb; ++c) t.weights.ih[r][c] = s.kLstmWeightIh[r][c];
      for (int c = 0; c < M::kHidden; ++c) t.weights.hh[r][c] = s.kLstmWeightHh[r][c];
    }
    for (int r = 0; r < M::kY; ++r)
      for (int c = 0; c < M::kHidden; ++c) t.weights.dec[r][c] = s.kDecWeight[r][c];
  }
  for (int r = 0; r < ModelTensors<M>::kPbRows; ++r) {
    for (int i = 0; i < M::kPb; ++i) t.pb_table[r][i] = s.kPbTable[r][i];
    const char* name = s.kStateNames[r];
    int n = 0;
    for (; name != nullptr && name[n] != '\0' && n < kStateNameBytes - 1; ++n) t.state_names[r][n] = name[n];
    for (; n < kStateNameBytes; ++n) t.state_names[r][n] = '\0';
  }
  for (int i = 0; i < M::kPb; ++i) t.detect_pb[i] = s.kDetectPb[i];
  for (int i = 0; i < M::kControlAlphaCount; ++i) t.control_alpha[i] = s.kControlAlpha[i];
}

template <GeneratedModel M>
constexpr ModelTensors<M> make_compiled_tensors() noexcept {
  ModelTensors<M> t{};
  build_tensors<M>(M{}, t);
  return t;
}

// The compiled-in model (read-only data: flash on the MCU).
template <GeneratedModel M>
inline constexpr ModelTensors<M> kCompiledTensors = make_compiled_tensors<M>();

// Whether the curve knots of `t` (a model image's: data, unlike the
// compiled-in model's, which curves_valid() checks at compile time) are
// finite and strictly increasing, levels and readings: the sensor stage
// divides by their differences. A signed image is the host's, which checks
// them; the runtime's self-test of an image refuses one that fails here.
template <GeneratedModel M>
constexpr bool curve_tensors_valid(const ModelTensors<M>& t) noexcept {
  // Finite: v - v is 0 only for a finite v (NaN and infinities give NaN).
  const auto finite = [](float v) { return v - v == 0.0f; };
  for (int j = 0; j < M::kCurveCount; ++j)
    for (int k = j * M::kCurveKnots; k < (j + 1) * M::kCurveKnots; ++k) {
      if (!finite(t.curve_level[k]) || !finite(t.curve_reading[k])) return false;
      if (k > j * M::kCurveKnots &&
          !(t.curve_level[k] > t.curve_level[k - 1] && t.curve_reading[k] > t.curve_reading[k - 1]))
        return false;
    }
  return true;
}

// The bytes of ModelTensors<M>'s members, each after the previous with no
// padding, plus tail padding to the struct's alignment: sizeof(ModelTensors<M>)
// must equal it on every target (no interior padding, so one layout).
template <GeneratedModel M>
constexpr std::size_t unpadded_tensor_bytes() noexcept {
  using T = ModelTensors<M>;
  constexpr std::size_t members =
      sizeof(T::model_hash) + sizeof(T::detect_threshold_sq) + sizeof(T::x_mean) + sizeof(T::x_inv_std) + sizeof(T::u_mean) +
      sizeof(T::u_std) + sizeof(T::u_inv_std) + sizeof(T::y_mean) + sizeof(T::y_std) + sizeof(T::y_inv_std) +
      sizeof(T::detect_threshold) + sizeof(T::crosstalk_gain) + sizeof(T::drift_rate) + sizeof(T::clip_rail) +
      sizeof(T::curve_level) + sizeof(T::curve_reading) +
      sizeof(T::enc_bias) + sizeof(T::lstm_bias) + sizeof(T::dec_bias) + sizeof(T::weights) +
      sizeof(T::pb_table) + sizeof(T::detect_pb) + sizeof(T::detect_mean) + sizeof(T::detect_whiten) +
      sizeof(T::control_alpha) + sizeof(T::loss_weight_up) + sizeof(T::loss_weight_down) +
      sizeof(T::clip_rail_model) + sizeof(T::state_names);
  return (members + alignof(T) - 1) / alignof(T) * alignof(T);
}

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_MODEL_TENSORS_H_
