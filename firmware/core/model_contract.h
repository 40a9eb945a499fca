// What a generated model provides to the firmware core (docs/method.md, "Network"; docs/architecture.md §6).
//
// `hadynet codegen MODEL --numeric q15|f32` writes one header holding one
// struct (default `hadynet::model_q15::Model` / `hadynet::model_f32::Model`)
// whose static constexpr members are listed below. The core's templates take
// that struct as their parameter; every buffer of the core is sized from its
// dimensions at compile time. The arrays are static constexpr members, so
// they live once in read-only data (flash on the MCU), never on the stack.
//
// Units. The network works in standardised units (physical minus mean,
// divided by std, per channel, as the trainer). The core converts at its
// boundary: physical float32 in, physical float32 out (kXMean/kXInvStd etc.).
//
// Numerics. kNumeric selects how `Value` and `Bias` are read:
//  * kQ15: Value = int16 in a per-tensor Q format (frac-bit counts below),
//    Bias = int32 already in its accumulator's format, so adding it is exact.
//    All arithmetic is integer (firmware/core/fixed_point.h), saturating.
//  * kF32: Value = Bias = float; the kFrac* constants are 0 and unused.
//
// Fixed-point formats (frac bits; a Q(F) raw v means v / 2^F):
//   kFracIn      x, u and p (the encoder input [x;p] and the LSTM input [u;p])
//   kFracH       h_0 .. h_N (encoder output and LSTM hidden state)
//   kFracC       LSTM cell state c
//   kFracY       decoder output y (and the detection mean / error e)
//   kFracGate    gate pre-activations: 12, the activation tables' input Q3.12
//   kFracEncW    folded encoder weight;  encoder bias is Q(kFracEncW + kFracIn)
//   kFracLstmW   both LSTM weight matrices; bias (b_ih + b_hh) is
//                Q(kFracLstmAcc), kFracLstmAcc = kFracLstmW + max(kFracIn, kFracH)
//   kFracDecW    decoder weight; decoder bias is Q(kFracDecW + kFracH)
//   kFracWhiten  detection whitening matrix
//   kFracZ       whitened detection error z (d = |z|)
//   kFracLossW   controller loss weights
#ifndef HADYNET_FIRMWARE_CORE_MODEL_CONTRACT_H_
#define HADYNET_FIRMWARE_CORE_MODEL_CONTRACT_H_

#include <concepts>
#include <cstdint>
#include <string_view>
#include <type_traits>

namespace hadynet::firmware {

enum class Numeric { kQ15, kF32 };

// The one spelling of a numeric in options, file names and messages.
constexpr const char* numeric_name(Numeric n) noexcept { return n == Numeric::kQ15 ? "q15" : "f32"; }
// "q15" or "f32"; false (and `out` untouched) for anything else.
constexpr bool parse_numeric(std::string_view text, Numeric& out) noexcept {
  if (text == "q15") {
    out = Numeric::kQ15;
  } else if (text == "f32") {
    out = Numeric::kF32;
  } else {
    return false;
  }
  return true;
}

// The version of this contract; codegen writes the same number into
// kContractVersion (kGeneratorVersion names the generator, not the contract)
// and the core rejects other versions at compile time (a stale generated
// header fails the build, not the robot). 3 added kPeriodUs and kBoardGroup,
// 4 kShapeId, 5 DerivedKind::kLag and kUDerivedLag, 6 the sensors'
// calibration curves (kCurve*), 7 no transposed copy of W_ih's command
// columns in the q15 tensors (model_tensors.h: a payload 8 KiB shorter), 8
// a load drift driven by the level, the reading less its bias (sensor_stage.h).
inline constexpr int kModelContractVersion = 8;

// Loss class of each observed channel for the grasp stabiliser.
enum class LossClass : std::uint8_t {
  kNone = 0,    // not in the loss
  kForce = 1,   // F = (f, f_contact): weight 1 if est >= ref, else beta
  kAngle = 2,   // theta: weight w2
  kLength = 3,  // l: weight w3
};

// The kind of a command channel: a command the host sets (kNone), or one
// computed from another command (trainer::DerivedKind, trainer/derived_inputs.h)
// that the firmware computes and the stabiliser never sets.
enum class DerivedKind : std::uint8_t {
  kNone = 0,        // a command
  kSign = 1,        // sign(u_base): -1, 0, +1
  kHysteresis = 2,  // sign of the last non-zero u_base (0 before the first)
  kChangeSign = 3,        // sign(u_base - u_base of the previous frame); 0 in the first frame
  kChangeHysteresis = 4,  // sign of the last non-zero change of u_base (0 before the first)
  kLag = 5,               // u_base of kUDerivedLag frames earlier (0 before the first command)
};
// The longest lag a kLag input may state (frames).
inline constexpr int kMaxDerivedLag = 20;

// clang-format off
template <class M>
concept GeneratedModel = requires {
  // ---- identity
  { M::kContractVersion } -> std::convertible_to<int>;        // == kModelContractVersion
  { M::kGeneratorVersion } -> std::convertible_to<const char*>; // e.g. "hadynet-codegen 0.1.0"
  { M::kModelHash } -> std::convertible_to<std::uint64_t>;     // FNV-1a 64 of the model file bytes
  // FNV-1a 64 of every member that is not model data (codegen/shape_id.h):
  // a model image (docs/model-update.md) runs only in a firmware of its shape.
  { M::kShapeId } -> std::convertible_to<std::uint64_t>;
  { M::kNumeric } -> std::convertible_to<Numeric>;
  typename M::Value;                                           // int16_t (q15) or float (f32)
  typename M::Bias;                                            // int32_t (q15) or float (f32)

  // ---- dimensions (all >= 1 except kStates >= 0)
  { M::kX } -> std::convertible_to<int>;          // initial-state features (paper: 37)
  { M::kU } -> std::convertible_to<int>;          // commands (8)
  { M::kY } -> std::convertible_to<int>;          // observed channels (27)
  { M::kPb } -> std::convertible_to<int>;         // parametric bias size (8)
  { M::kHidden } -> std::convertible_to<int>;     // LSTM units (128)
  { M::kStates } -> std::convertible_to<int>;     // rows of the PB table
  { M::kTrainSteps } -> std::convertible_to<int>; // N_train
  // The control period the model was trained at (its logs' dt_s), in whole
  // microseconds: one network step. The firmware's loop must run at it; an
  // image checks it against its board's period at compile time
  // (firmware/app/firmware_main.cc).
  { M::kPeriodUs } -> std::convertible_to<std::uint32_t>;

  // ---- formats (see above; 0 in an f32 model)
  { M::kFracIn } -> std::convertible_to<int>;
  { M::kFracH } -> std::convertible_to<int>;
  { M::kFracC } -> std::convertible_to<int>;
  { M::kFracY } -> std::convertible_to<int>;
  { M::kFracGate } -> std::convertible_to<int>;
  { M::kFracEncW } -> std::convertible_to<int>;
  { M::kFracLstmW } -> std::convertible_to<int>;
  { M::kFracLstmAcc } -> std::convertible_to<int>;
  { M::kFracDecW } -> std::convertible_to<int>;
  { M::kFracWhiten } -> std::convertible_to<int>;
  { M::kFracZ } -> std::convertible_to<int>;
  { M::kFracLossW } -> std::convertible_to<int>;

  // ---- channels and standardisation (float32, physical units)
  // x channel i is y channel kXSource[i] at t (kXIsDelta[i] false) or
  // y[t] - y[t-1] of that channel (true).
  M::kXSource;    // const int[kX]
  M::kXIsDelta;   // const bool[kX]
  M::kXMean;      // const float[kX]
  M::kXInvStd;    // const float[kX]   1 / std
  M::kUMean;      // const float[kU]
  M::kUStd;       // const float[kU]
  M::kUInvStd;    // const float[kU]
  M::kYMean;      // const float[kY]
  M::kYStd;       // const float[kY]
  M::kYInvStd;    // const float[kY]
  M::kYNames;     // const char* const[kY]
  M::kUNames;     // const char* const[kU]
  // The log group of the observed channels the board measures itself (the
  // robot profile's board_group; the hand: "fc", its loadcells fc0..fc8):
  // y channel "<group><k>" is the board's reading k
  // (firmware/app/channel_layout.h). "" for a model whose logs name none.
  M::kBoardGroup;  // const char[]

  // ---- network (standardised units)
  M::kEncWeight;     // Value[kHidden][kX + kPb]   BN folded; input [x ; p]
  M::kEncBias;       // Bias[kHidden]
  M::kLstmWeightIh;  // Value[4*kHidden][kU + kPb] gate order i, f, g, o; input [u ; p]
  M::kLstmWeightHh;  // Value[4*kHidden][kHidden]
  M::kLstmBias;      // Bias[4*kHidden]            b_ih + b_hh
  M::kDecWeight;     // Value[kY][kHidden]
  M::kDecBias;       // Bias[kY]

  // ---- PB table (Q(kFracIn) or float), with labels
  M::kPbTable;       // Value[max(kStates,1)][kPb]
  M::kStateNames;    // const char* const[max(kStates,1)]
  M::kStateObjects;  // const char* const[max(kStates,1)]

  // ---- contact detection (kHasDetection false: zeros, never used)
  { M::kHasDetection } -> std::convertible_to<bool>;
  { M::kDetectSteps } -> std::convertible_to<int>;  // N_detect (>= 1)
  M::kDetectPb;           // Value[kPb]           PB the detector runs with
  M::kDetectMean;         // Value[kY]            mu_e, Q(kFracY)
  M::kDetectWhiten;       // Value[kY][kY]        W with W^T W = Sigma_e^-1 (regularised)
  M::kDetectThreshold;    // float                C_detect on d
  M::kDetectThresholdSq;  // q15: int64 C_detect^2 in Q(2*kFracZ); f32: float C_detect^2

  // ---- grasp stabiliser (seed paper III-F; defaults of the generator)
  { M::kControlHorizon } -> std::convertible_to<int>;     // N_control (8)
  { M::kControlEpochs } -> std::convertible_to<int>;      // N_epoch (3)
  { M::kControlAlphaCount } -> std::convertible_to<int>;  // N_batch (4)
  { M::kControlTruncation } -> std::convertible_to<int>;  // K; >= kControlHorizon = full BPTT
  M::kControlAlpha;       // Value[kControlAlphaCount] step sizes, Q(kFracIn): L2 norm of
                          // the step of the whole standardised command sequence
  M::kLossClass;          // LossClass[kY]
  M::kLossWeightUp;       // Value[kY] weight where est >= ref, Q(kFracLossW)
  M::kLossWeightDown;     // Value[kY] weight where est <  ref, Q(kFracLossW)
  M::kControlActive;      // bool[kU]  commands the stabiliser may change (others: "no change")

  // ---- derived inputs (DerivedKind, as trainer::DerivedKind; a model fixed
  // for friction or input dead time has some)
  M::kUDerived;           // DerivedKind[kU]
  M::kUDerivedBase;       // int[kU]  the command it is computed from (itself for kNone)
  M::kUDerivedLag;        // int[kU]  steps, 1..kMaxDerivedLag for kLag; 0 otherwise

  // ---- sensor model (trainer/sensor_model.h; counts 0 for a model trained on
  // logs as they are; arrays hold max(count, 1) entries). The measured y is
  //   y_c = clip( g_c(y'_c) + sum k y'_s + rate D_c ),  y' the network's channel,
  // g_c the channel's calibration curve (the identity without one),
  // D_c the accumulated level since reset, the reading less its bias,
  // D_c <- (D_c + |y_c| kSensorPeriod) / (1 + rate kSensorPeriod) each frame
  // (load), or t kSensorPeriod (time).
  { M::kCurveCount } -> std::convertible_to<int>;  // at most one curve per channel
  { M::kCurveKnots } -> std::convertible_to<int>;  // knots of every curve (>= 2; 2 without a curve)
  M::kCurveChannel;       // int[]
  // g of curve j is piecewise linear through (level, reading) of its knots
  // [j * kCurveKnots, (j + 1) * kCurveKnots), both strictly increasing,
  // continued beyond the end knots along the end segments.
  M::kCurveLevel;         // float[] physical, the model's frame (y')
  M::kCurveReading;       // float[] physical, as the sensor reports it
  { M::kCrosstalkCount } -> std::convertible_to<int>;
  M::kCrosstalkTarget;    // int[]  y channel that picks up
  M::kCrosstalkSource;    // int[]  y channel it picks up from
  M::kCrosstalkGain;      // float[] target units per source unit
  { M::kDriftCount } -> std::convertible_to<int>;
  M::kDriftChannel;       // int[]
  M::kDriftIsLoad;        // bool[] true: D = accumulated level (the reading less its bias); false: time
  M::kDriftRate;          // float[] units per (unit s), or per s
  { M::kSensorPeriod } -> std::convertible_to<float>;  // s per frame for D
  { M::kClipCount } -> std::convertible_to<int>;
  M::kClipChannel;        // int[]
  M::kClipSide;           // int[]  +1: min(., rail); -1: max(., rail)
  M::kClipRail;           // float[] physical
  M::kClipRailModel;      // Value[] the rail on the network's channel, standardised, Q(kFracY):
                          // g^-1(rail) with a curve; the type's extreme (never clips) for a
                          // cross-talk target or a drifting channel (frame_rail, trainer/sensor_model.h)
};
// clang-format on

// The longest lag of M's kLag inputs (steps; 1 without any).
template <GeneratedModel M>
constexpr int longest_command_lag() noexcept {
  int longest = 1;
  for (int i = 0; i < M::kU; ++i)
    if (M::kUDerived[i] == DerivedKind::kLag && M::kUDerivedLag[i] > longest) longest = M::kUDerivedLag[i];
  return longest;
}

// The contract's curves: kCurveKnots >= 2, each on a distinct y channel, and
// the knots of M's own arrays strictly increasing (a model image's knots are
// checked by codegen when the image is written).
template <GeneratedModel M>
constexpr bool curves_valid() noexcept {
  if (M::kCurveCount < 0 || M::kCurveKnots < 2) return false;
  for (int j = 0; j < M::kCurveCount; ++j) {
    if (M::kCurveChannel[j] < 0 || M::kCurveChannel[j] >= M::kY) return false;
    for (int i = 0; i < j; ++i)
      if (M::kCurveChannel[i] == M::kCurveChannel[j]) return false;
    for (int k = j * M::kCurveKnots + 1; k < (j + 1) * M::kCurveKnots; ++k)
      if (!(M::kCurveLevel[k] > M::kCurveLevel[k - 1] && M::kCurveReading[k] > M::kCurveReading[k - 1])) return false;
  }
  return true;
}

// The contract's kUDerivedLag: 1..kMaxDerivedLag for a kLag input, 0 otherwise.
template <GeneratedModel M>
constexpr bool command_lags_valid() noexcept {
  for (int i = 0; i < M::kU; ++i) {
    const bool lag = M::kUDerived[i] == DerivedKind::kLag;
    if (lag ? (M::kUDerivedLag[i] < 1 || M::kUDerivedLag[i] > kMaxDerivedLag) : M::kUDerivedLag[i] != 0) return false;
  }
  return true;
}

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_MODEL_CONTRACT_H_
