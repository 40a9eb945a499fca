// The fixed-point formats of a q15 header (docs/codegen.md, "Formats"): the
// rule that turns a largest magnitude into frac bits, and the choice of every
// kFrac* of the contract (firmware/core/model_contract.h) from the model's
// measured value ranges, weights, PB table, detection statistics and control
// constants.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace hadynet::codegen {

struct PreparedModel;

// The activation tables' input format, Q3.12 (firmware/core/activation.h).
inline constexpr int kFracGate = 12;
// |z| up to this many C_detect must fit Q(kFracZ).
inline constexpr double kZBoundFactor = 4.0;

// The format rule: for a largest magnitude m >= 0,
//   F = 15 - ceil(log2 m), clamped to [0, 15], then lowered while
//   round(m 2^F) > 32767 (rounding half away from zero, as real_to_fixed),
// so that m and -m fit an int16 Q(F); m == 0 gives 15. Throws
// UnsupportedModel naming `what` when m is negative or not finite, or does
// not fit even Q0 (round(m) > 32767).
int frac_bits_for(double max_abs, const std::string& what = "value");

// real * 2^frac rounded half away from zero: firmware/core/fixed_point.h's
// real_to_fixed<int64_t, frac> (0 <= frac <= 62).
std::int64_t to_fixed(double real, int frac);

// One chosen format and where it came from.
struct FormatChoice {
  int frac = 0;      // frac bits of Q(frac)
  double m = 0;      // largest magnitude the format must hold (0 for fixed formats)
  std::string from;  // e.g. "1.5 x |h| 3.21" or "fixed: activation input Q3.12"
};

// Every kFrac* of the contract (q15; an f32 header writes 0 for all).
struct Formats {
  FormatChoice in, h, c, y, gate, enc_w, lstm_w, lstm_acc, dec_w, whiten, z, loss_w;
};

// The formats of a prepared model (all "unused" for f32); its
// options.target_formats when set (apply_target_formats).
Formats choose_formats(const PreparedModel& prepared);

// Replaces the chosen formats `f` by `target` (CodegenOptions::target_formats'
// order). Throws UnsupportedModel when a target format holds less than the
// model needs (fewer frac bits than chosen), or differs from a fixed or
// derived one (kFracGate, kFracLstmAcc, fixed kFracLossW).
void apply_target_formats(const std::array<int, 12>& target, Formats& f);

}  // namespace hadynet::codegen
