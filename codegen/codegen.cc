#include "codegen/codegen.h"

#include <Eigen/Core>
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <utility>

#include "codegen/header_text.h"
#include "codegen/prepared_model.h"
#include "codegen/sensor_arrays.h"
#include "codegen/shape_id.h"
#include "codegen/tensor_writer.h"
#include "trainer/model_file.h"

#ifndef HADYNET_CODEGEN_VERSION
#error "HADYNET_CODEGEN_VERSION must be defined by the build (the project version)"
#endif

namespace hadynet::codegen {

using trainer::HadynetModel;

namespace {

// Every value of the header as literals in its numeric (the quantisation step).
struct HeaderValues {
  std::vector<std::vector<std::string>> enc_w, lstm_ih, lstm_hh, dec_w, pb_table, det_whiten;
  std::vector<std::string> enc_b, lstm_b, dec_b, det_pb, det_mean, alphas, loss_up, loss_down;
  std::string threshold_sq;         // C_detect^2: q15 int64 in Q(2 kFracZ), f32 float
  SensorArrays sensor;
  std::vector<std::string> report;  // the largest quantisation error per tensor (comment lines)
};

// Quantises every tensor into the formats `f` (throws UnsupportedModel when a
// value does not fit, before any text exists).
HeaderValues quantise(const PreparedModel& p, const Formats& f) {
  const HadynetModel& model = p.model;
  const CodegenOptions& options = p.options;
  const bool q15 = options.numeric == Numeric::kQ15;
  const trainer::HadynetDims& d = model.params.dims;
  const trainer::FoldedEncoder& enc = p.encoder;
  const ControlOptions& ctl = options.control;
  const int pb_rows = std::max(d.states, 1);
  TensorWriter tw{options.numeric, {}};
  HeaderValues v;
  v.enc_w = tw.rows("kEncWeight", d.hidden, d.x + d.pb, f.enc_w.frac, false,
                             [&](Eigen::Index i, Eigen::Index j) { return double{enc.weight(i, j)}; });
  v.enc_b = tw.vector("kEncBias", d.hidden, f.enc_w.frac + f.in.frac, true,
                               [&](Eigen::Index i) { return double{enc.bias(i)}; });
  v.lstm_ih = tw.rows("kLstmWeightIh", 4 * d.hidden, d.u + d.pb, f.lstm_w.frac, false,
                               [&](Eigen::Index i, Eigen::Index j) {
                                 return double{model.params.lstm_weight_ih(i, j)};
                               });
  v.lstm_hh = tw.rows("kLstmWeightHh", 4 * d.hidden, d.hidden, f.lstm_w.frac, false,
                               [&](Eigen::Index i, Eigen::Index j) {
                                 return double{model.params.lstm_weight_hh(i, j)};
                               });
  // b_ih + b_hh in double (exact for all but extreme exponent differences), rounded once.
  v.lstm_b = tw.vector("kLstmBias", 4 * d.hidden, f.lstm_acc.frac, true, [&](Eigen::Index i) {
    return double{model.params.lstm_bias_ih(i)} + double{model.params.lstm_bias_hh(i)};
  });
  v.dec_w = tw.rows("kDecWeight", d.y, d.hidden, f.dec_w.frac, false,
                             [&](Eigen::Index i, Eigen::Index j) { return double{model.params.dec_weight(i, j)}; });
  v.dec_b = tw.vector("kDecBias", d.y, f.dec_w.frac + f.h.frac, true,
                               [&](Eigen::Index i) { return double{model.params.dec_bias(i)}; });
  v.pb_table = tw.rows("kPbTable", pb_rows, d.pb, f.in.frac, false,
                                [&](Eigen::Index i, Eigen::Index j) {
                                  return d.states > 0 ? double{model.params.pb(i, j)} : 0.0;
                                });
  const trainer::DetectionCalibration* det = model.detection ? &*model.detection : nullptr;
  const Eigen::MatrixXd whiten = p.whitening.value_or(Eigen::MatrixXd::Zero(d.y, d.y));
  v.det_pb = tw.vector("kDetectPb", d.pb, f.in.frac, false,
                                [&](Eigen::Index i) { return det ? det->pb(i) : 0.0; });
  v.det_mean = tw.vector("kDetectMean", d.y, f.y.frac, false,
                                  [&](Eigen::Index i) { return det ? det->mean(i) : 0.0; });
  v.det_whiten = tw.rows("kDetectWhiten", d.y, d.y, f.whiten.frac, false,
                                  [&](Eigen::Index i, Eigen::Index j) { return whiten(i, j); });
  v.alphas = tw.vector("kControlAlpha", static_cast<Eigen::Index>(ctl.alphas.size()),
                                f.in.frac, false, [&](Eigen::Index i) {
                                  return ctl.alphas[static_cast<std::size_t>(i)];
                                });
  if (q15) {
    for (std::size_t i = 0; i < ctl.alphas.size(); ++i) {
      if (to_fixed(ctl.alphas[i], f.in.frac) <= 0) {
        reject("control alpha " + num(ctl.alphas[i]) + " is below half an LSB of Q" +
               std::to_string(f.in.frac) + " (kFracIn) and would be 0");
      }
    }
  }
  v.loss_up = tw.vector("kLossWeightUp", d.y, f.loss_w.frac, false,
                                 [&](Eigen::Index i) { return p.loss_weights.up(i); });
  v.loss_down = tw.vector("kLossWeightDown", d.y, f.loss_w.frac, false,
                                   [&](Eigen::Index i) { return p.loss_weights.down(i); });
  v.sensor = sensor_arrays(model, q15, f.y.frac);
  const double threshold = det ? det->threshold : 0.0;
  if (q15) {
    v.threshold_sq = std::to_string(to_fixed(threshold * threshold, 2 * f.z.frac));
  } else {
    v.threshold_sq = float_literal(static_cast<float>(threshold * threshold));
  }
  v.report = std::move(tw.report);
  return v;
}

std::string format_line(const char* name, const FormatChoice& f) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "//   %-13s = %2d  ", name, f.frac);
  return comment_lines(buf, comment_text(f.from), "//                       ");
}

// The command-line options that reproduce `o`, one string per option.
std::vector<std::string> option_words(const CodegenOptions& o) {
  std::string alphas;
  for (std::size_t i = 0; i < o.control.alphas.size(); ++i)
    alphas += (i ? "," : "") + exact_num(o.control.alphas[i]);
  std::string commands;
  const std::vector<std::string>& names = o.control.commands.value();
  for (std::size_t i = 0; i < names.size(); ++i) commands += (i ? "," : "") + names[i];
  std::vector<std::string> words = {"--numeric " + std::string(numeric_name(o.numeric)),
          "--namespace " + namespace_of(o),
          "--headroom " + exact_num(o.headroom),
          "--control-horizon " + std::to_string(o.control.horizon),
          "--control-epochs " + std::to_string(o.control.epochs),
          "--control-alphas " + alphas,
          "--control-truncation " + std::to_string(o.control.truncation.value_or(o.control.horizon)),
          "--beta " + exact_num(o.control.loss.beta),
          "--w2 " + exact_num(o.control.loss.w2),
          "--w3 " + exact_num(o.control.loss.w3),
          std::string("--loss-units ") + (o.control.loss.physical_units ? "physical" : "standardised"),
          "--control-commands " + (names.empty() ? std::string("all") : commands)};
  if (o.period_s) words.push_back("--period-s " + exact_num(*o.period_s));
  return words;
}

// Stands for kShapeId's value until every member is known.
constexpr const char* kShapeIdPlaceholder = "@SHAPE_ID@";

// The header's text and every member's literals.
Emitter emit(const PreparedModel& p, const Formats& f, const HeaderValues& v, const ModelIdentity& identity) {
  const HadynetModel& model = p.model;
  const CodegenOptions& options = p.options;
  const bool q15 = options.numeric == Numeric::kQ15;
  const trainer::HadynetDims& d = model.params.dims;
  const trainer::ValueRanges& r = *model.ranges;
  const ControlOptions& ctl = options.control;
  const std::string ns = namespace_of(options);
  const trainer::DetectionCalibration* det = model.detection ? &*model.detection : nullptr;
  Emitter e;
  const std::string file_name = header_file_name(options.numeric);
  char hash_buf[32];
  std::snprintf(hash_buf, sizeof hash_buf, "0x%016llx", static_cast<unsigned long long>(identity.hash));
  const std::string hash_hex = hash_buf;
  const std::string generator = std::string("hadynet-codegen ") + HADYNET_CODEGEN_VERSION;
  const auto prov = [&](const char* key) {
    const auto it = model.provenance.find(key);
    return it == model.provenance.end() ? std::string("?") : comment_text(it->second);
  };

  e.line("// " + file_name + ": HADYNET model constants, generated by " + generator + ".");
  e.line("// Do not edit. Regenerate with:");
  {
    std::vector<std::string> words = {"hadynet codegen " + comment_text(identity.file_name),
                                      "--out DIR"};
    for (const std::string& w : option_words(options)) words.push_back(comment_text(w));
    std::string text = "//   ";
    std::size_t col = text.size();
    for (const std::string& w : words) {
      if (col > 5 && col + 1 + w.size() > kWidth) {
        e.line(text);
        text = "//     ";
        col = text.size();
      } else if (col > 5) {
        text += ' ';
        ++col;
      }
      text += w;
      col += w.size();
    }
    e.line(text);
  }
  e.line("//");
  const auto label = [](const std::string& name) {
    return "// " + name + std::string(11 - name.size(), ' ');
  };
  e.line(label("Contract") + "firmware/core/model_contract.h, version " +
         std::to_string(firmware::kModelContractVersion) + " (hadynet::firmware::GeneratedModel)");
  const std::string indent = "//            ";
  e.out += comment_lines(label("Model"), comment_text(identity.file_name) + ", FNV-1a 64 " + hash_hex,
                         indent);
  e.out += comment_lines(label("Trained"), "data_hash " + prov("data_hash") + ", git " +
                                             prov("git_commit") + ", " + prov("created_utc"),
                         indent);
  e.out += comment_lines(label("Dims"), "x " + std::to_string(d.x) + ", u " + std::to_string(d.u) +
                                             ", y " + std::to_string(d.y) + ", pb " +
                                             std::to_string(d.pb) + ", hidden " +
                                             std::to_string(d.hidden) + ", states " +
                                             std::to_string(d.states) + ", N_train " +
                                             std::to_string(model.train_steps),
                         indent);
  e.out += comment_lines(label("Ranges"), comment_text(r.source) + "; " +
                                             std::to_string(r.windows) + " windows",
                         indent);
  e.out += comment_lines(label("Detection"), det ? "N_detect " + std::to_string(det->steps) +
                                                    ", C_detect " + num(det->threshold) + ", " +
                                                    comment_text(det->source)
                                              : std::string("none (kHasDetection = false)"),
                         indent);
  e.line("//");
  if (q15) {
    e.line("// Fixed-point formats, frac bits F of Q(F) (raw v stands for v / 2^F). Rule: m is the");
    e.line("// largest |value| (activations: measured range x headroom " + num(options.headroom) +
           "; weights, biases, PBs");
    e.line("// and constants: their exact maximum); F = 15 - ceil(log2 m) clamped to [0, 15], then");
    e.line("// lowered while round(m 2^F) > 32767; m = 0 gives 15. Biases are int32 in their");
    e.line("// accumulator's format: encoder Q(EncW + In), LSTM Q(LstmAcc), decoder Q(DecW + H).");
    e.out += format_line("kFracIn", f.in);
    e.out += format_line("kFracH", f.h);
    e.out += format_line("kFracC", f.c);
    e.out += format_line("kFracY", f.y);
    e.out += format_line("kFracGate", f.gate);
    e.out += format_line("kFracEncW", f.enc_w);
    e.out += format_line("kFracLstmW", f.lstm_w);
    e.out += format_line("kFracLstmAcc", f.lstm_acc);
    e.out += format_line("kFracDecW", f.dec_w);
    e.out += format_line("kFracWhiten", f.whiten);
    e.out += format_line("kFracZ", f.z);
    e.out += format_line("kFracLossW", f.loss_w);
    e.line("//");
    e.line("// Largest quantisation error |q 2^-F - w| per tensor (real units, LSB of its format):");
    for (const std::string& l : v.report) e.line(l);
  } else {
    e.line("// float32: weights, biases and the PB table are the trainer's float32 values exactly;");
    e.line("// detection statistics, alphas and standardisation are rounded once from double. The");
    e.line("// kFrac* constants are 0 and unused.");
  }
  e.line("//");
  e.out += comment_lines("// ", "Measured ranges (max |v|, standardised units): x " + num(r.x) +
                                   ", u " + num(r.u) + ", encoder pre-activation " +
                                   num(r.enc_pre) + ", h " + num(r.h) + ", gate pre-activation " +
                                   num(r.gate_pre) + ", c " + num(r.c) + ", y " + num(r.y) + ".",
                         "// ");

  std::string guard = "HADYNET_GENERATED_";
  for (std::size_t i = 0; i < ns.size(); ++i) {
    if (ns.compare(i, 2, "::") == 0) {
      guard += '_';
      ++i;
    } else {
      guard += static_cast<char>(std::toupper(static_cast<unsigned char>(ns[i])));
    }
  }
  guard += std::string("_") + (q15 ? "Q15" : "F32") + "_H_";
  e.line("#ifndef " + guard);
  e.line("#define " + guard);
  e.line();
  e.line("#include <cstdint>");
  e.line();
  e.line("#include \"firmware/core/model_contract.h\"");
  e.line();
  e.line("namespace " + ns + " {");
  e.line();
  e.line("struct Model {");
  const std::string value_t = q15 ? "std::int16_t" : "float";
  const std::string bias_t = q15 ? "std::int32_t" : "float";
  e.line("  using Value = " + value_t + ";");
  e.line("  using Bias = " + bias_t + ";");
  e.line();
  e.line("  // ---- identity");
  e.member("int", "kContractVersion", std::to_string(firmware::kModelContractVersion));
  e.member("const char*", "kGeneratorVersion", string_literal(generator));
  e.member("std::uint64_t", "kModelHash", hash_hex + "ULL", "FNV-1a 64 of the model file");
  e.member("std::uint64_t", "kShapeId", kShapeIdPlaceholder, "model images must match it");
  e.member("hadynet::firmware::Numeric", "kNumeric",
           q15 ? "hadynet::firmware::Numeric::kQ15" : "hadynet::firmware::Numeric::kF32");
  e.line();
  e.line("  // ---- dimensions");
  e.member("int", "kX", std::to_string(d.x));
  e.member("int", "kU", std::to_string(d.u));
  e.member("int", "kY", std::to_string(d.y));
  e.member("int", "kPb", std::to_string(d.pb));
  e.member("int", "kHidden", std::to_string(d.hidden));
  e.member("int", "kStates", std::to_string(d.states));
  e.member("int", "kTrainSteps", std::to_string(model.train_steps));
  e.member("std::uint32_t", "kPeriodUs", std::to_string(p.period_us),
           "one network step, us (" + exact_num(p.period_s) + " s)");
  e.member("int", "kPbRows", "kStates > 0 ? kStates : 1", "rows of kPbTable");
  e.line();
  e.line("  // ---- formats (frac bits; 0 in an f32 model)");
  const auto frac = [&](const FormatChoice& c) { return std::to_string(q15 ? c.frac : 0); };
  e.member("int", "kFracIn", frac(f.in));
  e.member("int", "kFracH", frac(f.h));
  e.member("int", "kFracC", frac(f.c));
  e.member("int", "kFracY", frac(f.y));
  e.member("int", "kFracGate", frac(f.gate));
  e.member("int", "kFracEncW", frac(f.enc_w));
  e.member("int", "kFracLstmW", frac(f.lstm_w));
  e.member("int", "kFracLstmAcc", frac(f.lstm_acc));
  e.member("int", "kFracDecW", frac(f.dec_w));
  e.member("int", "kFracWhiten", frac(f.whiten));
  e.member("int", "kFracZ", frac(f.z));
  e.member("int", "kFracLossW", frac(f.loss_w));
  e.line();
  e.line("  // ---- channels and standardisation (float32, physical units)");
  std::vector<std::string> items;
  for (const int s : model.layout.x_source) items.push_back(std::to_string(s));
  e.array1("int", "kXSource[kX]", items);
  items.clear();
  for (const bool b : model.layout.x_is_delta) items.push_back(b ? "true" : "false");
  e.array1("bool", "kXIsDelta[kX]", items);
  e.array1("float", "kXMean[kX]", float_items(model.norm.x.mean));
  e.array1("float", "kXInvStd[kX]", inv_items(model.norm.x.std));
  e.array1("float", "kUMean[kU]", float_items(model.norm.u.mean));
  e.array1("float", "kUStd[kU]", float_items(model.norm.u.std));
  e.array1("float", "kUInvStd[kU]", inv_items(model.norm.u.std));
  e.array1("float", "kYMean[kY]", float_items(model.norm.y.mean));
  e.array1("float", "kYStd[kY]", float_items(model.norm.y.std));
  e.array1("float", "kYInvStd[kY]", inv_items(model.norm.y.std));
  e.array1("const char* const", "kYNames[kY]", string_items(model.layout.y_names));
  e.array1("const char* const", "kUNames[kU]", string_items(model.layout.u_names));
  e.member("char", "kBoardGroup[]", string_literal(model.profile.board_group),
           "y channels <group><k> are the board's readings k");
  e.line();
  e.line("  // ---- network (standardised units)");
  e.line("  // h_0 = ReLU(kEncWeight [x ; p] + kEncBias), batch norm folded in; gate order i, f, g, o.");
  e.array2("Value", "kEncWeight[kHidden][kX + kPb]", v.enc_w);
  e.array1("Bias", "kEncBias[kHidden]", v.enc_b);
  e.array2("Value", "kLstmWeightIh[4 * kHidden][kU + kPb]", v.lstm_ih);
  e.array2("Value", "kLstmWeightHh[4 * kHidden][kHidden]", v.lstm_hh);
  e.array1("Bias", "kLstmBias[4 * kHidden]", v.lstm_b);
  e.array2("Value", "kDecWeight[kY][kHidden]", v.dec_w);
  e.array1("Bias", "kDecBias[kY]", v.dec_b);
  e.line();
  e.line("  // ---- PB table (Q(kFracIn) or float), one row per dynamics state");
  e.array2("Value", "kPbTable[kPbRows][kPb]", v.pb_table);
  std::vector<std::string> names, objects;
  for (const trainer::PbState& s : model.states) {
    names.push_back(s.name);
    objects.push_back(s.object);
  }
  if (names.empty()) names = objects = {""};
  e.array1("const char* const", "kStateNames[kPbRows]", string_items(names));
  e.array1("const char* const", "kStateObjects[kPbRows]", string_items(objects));
  e.line();
  e.line("  // ---- contact detection: d = |kDetectWhiten (e - kDetectMean)|, contact when d > C_detect");
  e.member("bool", "kHasDetection", det ? "true" : "false");
  e.member("int", "kDetectSteps", std::to_string(det ? det->steps : 1));
  e.array1("Value", "kDetectPb[kPb]", v.det_pb);
  e.array1("Value", "kDetectMean[kY]", v.det_mean);
  e.array2("Value", "kDetectWhiten[kY][kY]", v.det_whiten);
  e.member("float", "kDetectThreshold", float_literal(static_cast<float>(det ? det->threshold : 0.0)));
  e.member(q15 ? "std::int64_t" : "float", "kDetectThresholdSq", v.threshold_sq,
           q15 ? "C_detect^2 in Q(2 kFracZ)" : "C_detect^2");
  e.line();
  e.line("  // ---- grasp stabiliser");
  e.member("int", "kControlHorizon", std::to_string(ctl.horizon));
  e.member("int", "kControlEpochs", std::to_string(ctl.epochs));
  e.member("int", "kControlAlphaCount", std::to_string(ctl.alphas.size()));
  e.member("int", "kControlTruncation", std::to_string(ctl.truncation.value_or(ctl.horizon)),
           ctl.truncation.value_or(ctl.horizon) >= ctl.horizon ? "full BPTT" : "truncated");
  e.array1("Value", "kControlAlpha[kControlAlphaCount]", v.alphas);
  items.clear();
  for (const firmware::LossClass c : p.loss_classes) {
    switch (c) {
      case firmware::LossClass::kForce: items.push_back("hadynet::firmware::LossClass::kForce"); break;
      case firmware::LossClass::kAngle: items.push_back("hadynet::firmware::LossClass::kAngle"); break;
      case firmware::LossClass::kLength: items.push_back("hadynet::firmware::LossClass::kLength"); break;
      case firmware::LossClass::kNone: items.push_back("hadynet::firmware::LossClass::kNone"); break;
    }
  }
  e.array1("hadynet::firmware::LossClass", "kLossClass[kY]", items);
  e.array1("Value", "kLossWeightUp[kY]", v.loss_up);
  e.array1("Value", "kLossWeightDown[kY]", v.loss_down);
  items.clear();
  for (const bool a : p.active_commands) items.push_back(a ? "true" : "false");
  e.array1("bool", "kControlActive[kU]", items);
  e.line();
  e.line("  // ---- derived inputs: computed by the firmware from their base command");
  e.array1("hadynet::firmware::DerivedKind", "kUDerived[kU]", v.sensor.derived);
  e.array1("int", "kUDerivedBase[kU]", v.sensor.derived_base);
  e.array1("int", "kUDerivedLag[kU]", v.sensor.derived_lag);
  e.line();
  e.line("  // ---- sensor model: measured y_c = clip(g_c(y'_c) + sum gain y'_source + rate D_c)");
  for (const std::string& l : v.sensor.notes) e.out += comment_lines("  // ", comment_text(l), "  //   ");
  e.member("int", "kCurveCount", std::to_string(v.sensor.curve_count));
  e.member("int", "kCurveKnots", std::to_string(v.sensor.curve_knots), "knots per curve");
  e.array1("int", "kCurveChannel[" + std::to_string(v.sensor.curve_channel.size()) + "]", v.sensor.curve_channel);
  e.array1("float", "kCurveLevel[" + std::to_string(v.sensor.curve_level.size()) + "]", v.sensor.curve_level);
  e.array1("float", "kCurveReading[" + std::to_string(v.sensor.curve_reading.size()) + "]", v.sensor.curve_reading);
  e.member("int", "kCrosstalkCount", std::to_string(v.sensor.crosstalk_count));
  e.array1("int", "kCrosstalkTarget[" + std::to_string(v.sensor.crosstalk_target.size()) + "]", v.sensor.crosstalk_target);
  e.array1("int", "kCrosstalkSource[" + std::to_string(v.sensor.crosstalk_source.size()) + "]", v.sensor.crosstalk_source);
  e.array1("float", "kCrosstalkGain[" + std::to_string(v.sensor.crosstalk_gain.size()) + "]", v.sensor.crosstalk_gain);
  e.member("int", "kDriftCount", std::to_string(v.sensor.drift_count));
  e.array1("int", "kDriftChannel[" + std::to_string(v.sensor.drift_channel.size()) + "]", v.sensor.drift_channel);
  e.array1("bool", "kDriftIsLoad[" + std::to_string(v.sensor.drift_is_load.size()) + "]", v.sensor.drift_is_load);
  e.array1("float", "kDriftRate[" + std::to_string(v.sensor.drift_rate.size()) + "]", v.sensor.drift_rate);
  e.member("float", "kSensorPeriod", v.sensor.period, "s per frame (drift integration)");
  e.member("int", "kClipCount", std::to_string(v.sensor.clip_count));
  e.array1("int", "kClipChannel[" + std::to_string(v.sensor.clip_channel.size()) + "]", v.sensor.clip_channel);
  e.array1("int", "kClipSide[" + std::to_string(v.sensor.clip_side.size()) + "]", v.sensor.clip_side);
  e.array1("float", "kClipRail[" + std::to_string(v.sensor.clip_rail.size()) + "]", v.sensor.clip_rail);
  e.array1("Value", "kClipRailModel[" + std::to_string(v.sensor.clip_rail_model.size()) + "]", v.sensor.clip_rail_model);
  e.line("};");
  e.line();
  e.line("static_assert(hadynet::firmware::GeneratedModel<Model>);");
  e.line();
  e.line("}  // namespace " + ns);
  e.line();
  e.line("#endif  // " + guard);

  char id_buf[32];
  std::snprintf(id_buf, sizeof id_buf, "0x%016llxULL", static_cast<unsigned long long>(shape_id(e.literals)));
  const std::size_t at = e.out.find(kShapeIdPlaceholder);
  e.out.replace(at, std::string(kShapeIdPlaceholder).size(), id_buf);
  e.literals["kShapeId"] = {id_buf};
  return e;
}


}  // namespace

std::string namespace_of(const CodegenOptions& options) {
  if (!options.ns.empty()) return options.ns;
  return std::string("hadynet::model_") + numeric_name(options.numeric);
}

std::string header_file_name(Numeric numeric) {
  return std::string("hadynet_model_") + numeric_name(numeric) + ".h";
}

Formats choose_formats(const HadynetModel& model, const CodegenOptions& options) {
  return choose_formats(prepare(model, options));
}

GeneratedHeader generate(const HadynetModel& model, const ModelIdentity& identity, const CodegenOptions& options) {
  const PreparedModel prepared = prepare(model, options);
  const Formats formats = choose_formats(prepared);
  const HeaderValues values = quantise(prepared, formats);
  Emitter e = emit(prepared, formats, values, identity);
  const std::uint64_t id = shape_id(e.literals);
  return {header_file_name(options.numeric), std::move(e.out), formats, id, std::move(e.literals)};
}

}  // namespace hadynet::codegen
