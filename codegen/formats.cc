#include "codegen/formats.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "codegen/checks.h"
#include "codegen/header_text.h"
#include "codegen/prepared_model.h"
#include "codegen/unsupported_model.h"
#include "firmware/core/fixed_point.h"

namespace hadynet::codegen {

namespace {

using ToFixedFn = std::int64_t (*)(double) noexcept;
template <std::size_t... F>
constexpr std::array<ToFixedFn, sizeof...(F)> to_fixed_table(std::index_sequence<F...>) {
  return {&fixed::real_to_fixed<std::int64_t, static_cast<int>(F), double>...};
}
constexpr auto kToFixed = to_fixed_table(std::make_index_sequence<63>{});

template <class M>
double max_abs(const M& m) {
  return m.size() == 0 ? 0.0 : static_cast<double>(m.cwiseAbs().maxCoeff());
}

}  // namespace

std::int64_t to_fixed(double real, int frac) {
  if (frac < 0 || frac > 62) throw std::invalid_argument("to_fixed: frac out of 0..62");
  return kToFixed[static_cast<std::size_t>(frac)](real);
}

int frac_bits_for(double max_abs, const std::string& what) {
  if (!std::isfinite(max_abs) || max_abs < 0) {
    reject(what + ": largest magnitude " + num(max_abs) + " is not a finite number >= 0");
  }
  if (max_abs == 0) return 15;
  int exponent = 0;
  const double mantissa = std::frexp(max_abs, &exponent);  // max_abs = mantissa 2^exponent, [0.5, 1)
  const int ceil_log2 = mantissa == 0.5 ? exponent - 1 : exponent;
  int frac = std::clamp(15 - ceil_log2, 0, 15);
  while (frac > 0 && to_fixed(max_abs, frac) > 32767) --frac;
  if (to_fixed(max_abs, frac) > 32767) {
    reject(what + ": largest magnitude " + num(max_abs) + " does not fit an int16 even in Q0");
  }
  return frac;
}

void apply_target_formats(const std::array<int, 12>& target, Formats& f) {
  static constexpr const char* kNames[12] = {"kFracIn",    "kFracH",     "kFracC",       "kFracY",
                                             "kFracGate",  "kFracEncW",  "kFracLstmW",   "kFracLstmAcc",
                                             "kFracDecW",  "kFracWhiten", "kFracZ",      "kFracLossW"};
  FormatChoice* choices[12] = {&f.in,     &f.h,        &f.c,        &f.y,      &f.gate,   &f.enc_w,
                               &f.lstm_w, &f.lstm_acc, &f.dec_w,    &f.whiten, &f.z,      &f.loss_w};
  for (int i = 0; i < 12; ++i) {
    FormatChoice& c = *choices[i];
    const int want = target[static_cast<std::size_t>(i)];
    if (want < 0 || want > 62) reject(std::string("target ") + kNames[i] + " " + std::to_string(want) + " is not a format");
    // The gate input is fixed (the activation tables' Q3.12) and the LSTM
    // accumulator derived from the other targets; any other target may hold
    // more range than the model needs (fewer frac bits), never less.
    bool ok = want <= c.frac;
    if (i == 4) ok = want == c.frac;
    if (i == 7) ok = want == target[6] + std::max(target[0], target[1]);
    if (!ok) {
      reject(std::string(kNames[i]) + ": this model needs Q" + std::to_string(c.frac) + " (" + c.from +
             "), the target firmware has Q" + std::to_string(want) +
             ": build a firmware for this model instead of a model image");
    }
    if (want != c.frac) c.from = "the target firmware's format (this model needs Q" + std::to_string(c.frac) + ")";
    c.frac = want;
  }
}

Formats choose_formats(const PreparedModel& prepared) {
  const trainer::HadynetModel& model = prepared.model;
  const CodegenOptions& options = prepared.options;
  Formats f;
  if (options.numeric == Numeric::kF32) {
    for (FormatChoice* c : {&f.in, &f.h, &f.c, &f.y, &f.gate, &f.enc_w, &f.lstm_w, &f.lstm_acc,
                            &f.dec_w, &f.whiten, &f.z, &f.loss_w}) {
      *c = {0, 0.0, "unused (f32)"};
    }
    return f;
  }
  const trainer::ValueRanges& r = *model.ranges;
  const double hr = options.headroom;
  const std::string h_text = num(hr) + " x ";
  const auto pick = [](double m, const std::string& what, std::string from) {
    return FormatChoice{frac_bits_for(m, what), m, std::move(from)};
  };

  const double pb_table = max_abs(model.params.pb);
  const double detect_pb = model.detection ? max_abs(model.detection->pb) : 0.0;
  const double alphas =
      *std::max_element(options.control.alphas.begin(), options.control.alphas.end());
  const double m_in = std::max({hr * r.x, hr * r.u, pb_table, detect_pb, alphas});
  f.in = pick(m_in, "kFracIn (x, u, PB, alphas)",
              "m " + num(m_in) + " = max(" + h_text + "|x| " + num(r.x) + ", " + h_text + "|u| " +
                  num(r.u) + ", |PB table| " + num(pb_table) + ", |detection PB| " +
                  num(detect_pb) + ", alphas " + num(alphas) + ")");
  f.h = pick(hr * r.h, "kFracH (h_0 .. h_N)",
             "m " + num(hr * r.h) + " = " + h_text + "|h| " + num(r.h) + " (h_0 = ReLU(encoder), LSTM h)");
  f.c = pick(hr * r.c, "kFracC (cell state)", "m " + num(hr * r.c) + " = " + h_text + "|c| " + num(r.c));
  const double detect_mean = model.detection ? max_abs(model.detection->mean) : 0.0;
  const double m_y = std::max(hr * r.y, detect_mean);
  f.y = pick(m_y, "kFracY (decoder output)",
             "m " + num(m_y) + " = max(" + h_text + "|y| " + num(r.y) + ", |mu_e| " +
                 num(detect_mean) + ")");
  f.gate = {kFracGate, 0.0,
            "fixed: activation input Q3.12 (measured |gate pre-activation| " + num(r.gate_pre) +
                "; the activations saturate beyond 8)"};

  const double enc_w = max_abs(prepared.encoder.weight);
  f.enc_w = pick(enc_w, "kFracEncW (folded encoder weight)", "m " + num(enc_w) + " = |folded encoder weight|");
  const double lstm_w =
      std::max(max_abs(model.params.lstm_weight_ih), max_abs(model.params.lstm_weight_hh));
  f.lstm_w = pick(lstm_w, "kFracLstmW (LSTM weights)", "m " + num(lstm_w) + " = max |W_ih|, |W_hh|");
  f.lstm_acc = {f.lstm_w.frac + std::max(f.in.frac, f.h.frac), 0.0,
                "kFracLstmW + max(kFracIn, kFracH) (int32 LSTM bias format)"};
  const double dec_w = max_abs(model.params.dec_weight);
  f.dec_w = pick(dec_w, "kFracDecW (decoder weight)", "m " + num(dec_w) + " = |decoder weight|");

  if (model.detection) {
    const double w = max_abs(*prepared.whitening);
    f.whiten = pick(w, "kFracWhiten (detection whitening)", "m " + num(w) + " = |W|, W^T W = Sigma_e^-1");
    const double z = kZBoundFactor * model.detection->threshold;
    f.z = pick(z, "kFracZ (whitened error)",
               "m " + num(z) + " = 4 x C_detect " + num(model.detection->threshold));
  } else {
    f.whiten = {15, 0.0, "no detection calibration"};
    f.z = {15, 0.0, "no detection calibration"};
  }
  if (options.control.loss.physical_units) {
    f.loss_w = pick(1.0, "kFracLossW (loss weights)", "m 1 = the largest weight (physical units, normalised)");
  } else {
    f.loss_w = {kFracLossW, 0.0, "fixed: loss weights up to 7.99 (standardised units)"};
  }
  if (options.target_formats) apply_target_formats(*options.target_formats, f);
  return f;
}

}  // namespace hadynet::codegen
