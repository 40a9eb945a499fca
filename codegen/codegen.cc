#include "codegen/codegen.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include "datalog/atomic_file.h"
#include "datalog/content_hash.h"
#include "firmware/core/fixed_point.h"
#include "trainer/derived_inputs.h"
#include "trainer/deploy_prep.h"
#include "trainer/log_dataset.h"
#include "trainer/model_file.h"
#include "trainer/safetensors.h"

#ifndef HADYNET_CODEGEN_VERSION
#error "HADYNET_CODEGEN_VERSION must be defined by the build (the project version)"
#endif

namespace hadynet::codegen {

namespace fs = std::filesystem;
using trainer::HadynetModel;

namespace {

constexpr int kFracGate = 12;    // activation tables' input, Q3.12 (firmware/core/activation.h)
constexpr int kFracLossW = 12;   // loss weights up to 32767 / 4096 = 7.99976
constexpr double kMaxLossWeight = 32767.0 / 4096.0;
constexpr double kZBoundFactor = 4.0;  // |z| up to 4 C_detect must fit Q(kFracZ)
constexpr std::size_t kWidth = 100;    // generated lines stay within this many columns

[[noreturn]] void reject(const std::string& message) { throw UnsupportedModel(message); }

template <class M>
double max_abs(const M& m) {
  return m.size() == 0 ? 0.0 : static_cast<double>(m.cwiseAbs().maxCoeff());
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// The shortest "%.Ng" text that reads back as exactly v.
std::string exact_num(double v) {
  char buf[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

// ---- literals ---------------------------------------------------------------

// A float literal that reads back as exactly `v` ("%.9g" round-trips float).
std::string float_literal(float v) {
  if (!std::isfinite(v)) reject("a value is not finite in float32");
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
  const float back = std::strtof(buf, nullptr);
  if (std::memcmp(&back, &v, sizeof v) != 0) {
    throw std::logic_error(std::string("codegen: float literal ") + buf + " does not round-trip");
  }
  std::string s = buf;
  if (s.find_first_of(".e") == std::string::npos) s += ".0";  // "1" -> "1.0f", "-0" -> "-0.0f"
  return s + "f";
}

// A C++ string literal; quotes, backslashes and bytes outside printable ASCII
// as escapes (octal, three digits, so no following character can extend them).
std::string string_literal(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20 || c >= 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\%03o", static_cast<unsigned>(c));
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

// Text safe inside a // comment: no line breaks, no line-continuing backslash.
std::string comment_text(const std::string& s) {
  std::string out;
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    out += (c < 0x20 || c == 0x7f || c == '\\') ? '?' : ch;
  }
  return out;
}

// `text` as // comment lines within kWidth columns, broken at spaces; the
// first line starts with `prefix`, the others with `continuation`.
std::string comment_lines(const std::string& prefix, const std::string& text,
                          const std::string& continuation) {
  std::string out, line = prefix;
  std::size_t start = 0;
  bool first_word = true;
  while (start < text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    start = end + 1;
    if (word.empty()) continue;
    if (!first_word && line.size() + 1 + word.size() > kWidth) {
      out += line + "\n";
      line = continuation + word;
    } else {
      line += (first_word ? "" : " ") + word;
    }
    first_word = false;
  }
  return out + line + "\n";
}

// Items separated by ", ", wrapped before kWidth columns; the first item
// starts at column `first_col`, continuation lines at `indent`.
std::string wrapped(const std::vector<std::string>& items, std::size_t first_col,
                    std::size_t indent) {
  std::string s;
  std::size_t col = first_col;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string piece = items[i] + (i + 1 < items.size() ? "," : "");
    if (i > 0) {
      if (col + 1 + piece.size() > kWidth - 2) {  // room for a closing "};" or "},"
        s += '\n';
        s.append(indent, ' ');
        col = indent;
      } else {
        s += ' ';
        ++col;
      }
    }
    s += piece;
    col += piece.size();
  }
  return s;
}

// ---- quantisation -----------------------------------------------------------

using ToFixedFn = std::int64_t (*)(double) noexcept;
template <std::size_t... F>
constexpr std::array<ToFixedFn, sizeof...(F)> to_fixed_table(std::index_sequence<F...>) {
  return {&fixed::real_to_fixed<std::int64_t, static_cast<int>(F), double>...};
}
constexpr auto kToFixed = to_fixed_table(std::make_index_sequence<63>{});

// Quantises real values into Q(frac) of an int16 (value) or int32 (bias),
// tracking the largest error; rejects values that do not fit.
struct Quantiser {
  int frac;
  bool bias;          // int32 instead of int16
  std::string what;   // tensor name, for errors and the report
  double max_error = 0;  // real units

  std::int64_t operator()(double real, const std::string& where) {
    const std::int64_t q = to_fixed(real, frac);
    const std::int64_t lo = bias ? std::numeric_limits<std::int32_t>::min() : -32768;
    const std::int64_t hi = bias ? std::numeric_limits<std::int32_t>::max() : 32767;
    if (q < lo || q > hi) {
      reject(what + where + " = " + num(real) + " overflows " + (bias ? "int32" : "int16") +
             " in Q" + std::to_string(frac) +
             (bias ? " (its accumulator format): the weights or inputs need fewer fraction bits"
                   : ""));
    }
    max_error = std::max(max_error, std::abs(std::ldexp(static_cast<double>(q), -frac) - real));
    return q;
  }
};

std::string index_text(Eigen::Index r, Eigen::Index c = -1) {
  return "[" + std::to_string(r) + "]" + (c >= 0 ? "[" + std::to_string(c) + "]" : "");
}

// ---- checks -----------------------------------------------------------------

// An identifier that is not a keyword and not reserved (no leading '_', no "__").
bool valid_identifier(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0])) || s[0] == '_' ||
      s.find("__") != std::string::npos) {
    return false;
  }
  for (const char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  static const std::set<std::string> kKeywords = {
      "alignas", "alignof", "and", "asm", "auto", "bool", "break", "case", "catch", "char",
      "class", "const", "constexpr", "continue", "default", "delete", "do", "double", "else",
      "enum", "explicit", "export", "extern", "false", "float", "for", "friend", "goto", "if",
      "inline", "int", "long", "mutable", "namespace", "new", "noexcept", "not", "nullptr",
      "operator", "or", "private", "protected", "public", "register", "return", "short",
      "signed", "sizeof", "static", "struct", "switch", "template", "this", "throw", "true",
      "try", "typedef", "typename", "union", "unsigned", "using", "virtual", "void", "volatile",
      "while", "std"};
  return kKeywords.count(s) == 0;
}

void check_namespace(const std::string& ns) {
  std::size_t start = 0;
  while (true) {
    const std::size_t end = ns.find("::", start);
    const std::string part =
        ns.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (!valid_identifier(part)) {
      reject("namespace '" + ns + "' is not a C++ namespace name (identifiers joined by '::')");
    }
    if (end == std::string::npos) break;
    start = end + 2;
  }
}

// The options with every choice the caller left open taken from the model's
// robot profile (the stabiliser's commands and loss classes).
CodegenOptions with_profile(CodegenOptions o, const HadynetModel& model) {
  ControlOptions& c = o.control;
  const datalog::RobotProfile& p = model.profile;
  if (!c.commands) c.commands = p.control_commands;
  if (!c.force_groups) c.force_groups = p.force_groups;
  if (!c.angle_groups) c.angle_groups = p.angle_groups;
  if (!c.length_groups) c.length_groups = p.length_groups;
  return o;
}

// Loss class of each y channel, from the option's channel groups (options
// after with_profile()).
std::vector<firmware::LossClass> loss_classes(const HadynetModel& model, const ControlOptions& c) {
  const std::vector<std::string>& y = model.layout.y_names;
  std::vector<firmware::LossClass> classes(y.size(), firmware::LossClass::kNone);
  std::map<std::string, std::string> class_of_group;
  const auto assign = [&](const std::vector<std::string>& groups, firmware::LossClass cls,
                          const char* name) {
    for (const std::string& g : groups) {
      const auto [it, inserted] = class_of_group.emplace(g, name);
      if (!inserted) {
        reject("loss group '" + g + "' is in both the " + it->second + " and the " + name +
               " class");
      }
      bool any = false;
      for (std::size_t i = 0; i < y.size(); ++i) {
        if (trainer::channel_group(y[i]) == g) {
          classes[i] = cls;
          any = true;
        }
      }
      if (!any) reject(std::string(name) + " loss group '" + g + "' names no y channel of the model");
    }
  };
  assign(c.force_groups.value(), firmware::LossClass::kForce, "force");
  assign(c.angle_groups.value(), firmware::LossClass::kAngle, "angle");
  assign(c.length_groups.value(), firmware::LossClass::kLength, "length");
  return classes;
}

// kControlActive: which u channels the stabiliser may change.
std::vector<bool> active_commands(const HadynetModel& model, const ControlOptions& c) {
  const std::vector<std::string>& u = model.layout.u_names;
  // A derived input (sign_u0, hyst_u0: trainer/derived_inputs.h) is computed
  // from a command, so it is never one the stabiliser sets.
  std::vector<bool> active(u.size(), false);
  const std::vector<std::string>& commands = c.commands.value();
  if (commands.empty())
    for (std::size_t i = 0; i < u.size(); ++i) active[i] = !trainer::parse_derived_input(u[i]).has_value();
  for (const std::string& name : commands) {
    const auto it = std::find(u.begin(), u.end(), name);
    if (it == u.end()) reject("control command '" + name + "' is not a u channel of the model");
    if (trainer::parse_derived_input(name))
      reject("control command '" + name + "' is computed from another command (a derived input), not set by the stabiliser");
    active[static_cast<std::size_t>(it - u.begin())] = true;
  }
  return active;
}

// The derived-input and sensor-model arrays of the header (model_contract.h),
// as literals; arrays hold max(count, 1) entries (a zero entry when empty).
struct SensorArrays {
  std::vector<std::string> derived, derived_base;
  int crosstalk_count = 0, drift_count = 0, clip_count = 0;
  std::vector<std::string> crosstalk_target, crosstalk_source, crosstalk_gain;
  std::vector<std::string> drift_channel, drift_is_load, drift_rate;
  std::string period = "0.0f";
  std::vector<std::string> clip_channel, clip_side, clip_rail, clip_rail_model;
  std::vector<std::string> notes;  // comment lines
};

SensorArrays sensor_arrays(const HadynetModel& model, bool q15, int frac_y) {
  const auto& y = model.layout.y_names;
  const auto& u = model.layout.u_names;
  const auto y_index = [&](const std::string& name) -> Eigen::Index {
    const auto it = std::find(y.begin(), y.end(), name);
    if (it == y.end()) reject("sensor model names '" + name + "', not a y channel");
    return it - y.begin();
  };
  SensorArrays a;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const auto d = trainer::parse_derived_input(u[i]);
    if (!d) {
      a.derived.push_back("hadynet::firmware::DerivedKind::kNone");
      a.derived_base.push_back(std::to_string(i));
      continue;
    }
    const auto it = std::find(u.begin(), u.end(), d->base);
    if (it == u.end()) reject("derived input '" + u[i] + "': no command '" + d->base + "' in the model");
    if (trainer::parse_derived_input(d->base)) reject("derived input '" + u[i] + "' is derived from a derived input");
    a.derived.push_back(d->kind == trainer::DerivedKind::kSign ? "hadynet::firmware::DerivedKind::kSign"
                                                               : "hadynet::firmware::DerivedKind::kHysteresis");
    a.derived_base.push_back(std::to_string(it - u.begin()));
  }
  const trainer::SensorModel& s = model.sensor;
  for (const auto& x : s.crosstalk) {
    a.crosstalk_target.push_back(std::to_string(y_index(x.target)));
    a.crosstalk_source.push_back(std::to_string(y_index(x.source)));
    a.crosstalk_gain.push_back(float_literal(static_cast<float>(x.gain)));
  }
  for (const auto& d : s.drifts) {
    a.drift_channel.push_back(std::to_string(y_index(d.channel)));
    a.drift_is_load.push_back(d.load ? "true" : "false");
    a.drift_rate.push_back(float_literal(static_cast<float>(d.rate)));
  }
  if (!s.drifts.empty()) a.period = float_literal(static_cast<float>(s.period_s));
  for (const auto& c : s.clips) {
    const Eigen::Index r = y_index(c.channel);
    a.clip_channel.push_back(std::to_string(r));
    a.clip_side.push_back(std::to_string(c.side));
    a.clip_rail.push_back(float_literal(static_cast<float>(c.rail)));
    const double standardised = (c.rail - model.norm.y.mean(r)) / model.norm.y.std(r);
    a.clip_rail_model.push_back(
        q15 ? std::to_string(std::clamp<std::int64_t>(to_fixed(standardised, frac_y), -32768, 32767))
            : float_literal(static_cast<float>(standardised)));
  }
  a.crosstalk_count = static_cast<int>(a.crosstalk_target.size());
  a.drift_count = static_cast<int>(a.drift_channel.size());
  a.clip_count = static_cast<int>(a.clip_channel.size());
  for (auto* v : {&a.crosstalk_target, &a.crosstalk_source, &a.drift_channel, &a.clip_channel, &a.clip_side})
    if (v->empty()) v->push_back("0");
  for (auto* v : {&a.crosstalk_gain, &a.drift_rate, &a.clip_rail})
    if (v->empty()) v->push_back("0.0f");
  if (a.drift_is_load.empty()) a.drift_is_load.push_back("false");
  if (a.clip_rail_model.empty()) a.clip_rail_model.push_back(q15 ? "0" : "0.0f");
  for (const std::string& l : s.describe()) a.notes.push_back(l);
  for (const auto& d : s.delays)
    a.notes.push_back(d.channel + ": the firmware does not undo this delay (it needs future samples); the " +
                      "network sees the late measurement");
  return a;
}

void check_options(const HadynetModel& model, const CodegenOptions& given) {
  const CodegenOptions o = with_profile(given, model);
  check_namespace(namespace_of(o));
  if (!std::isfinite(o.headroom) || o.headroom < 1.0 || o.headroom > 1e6) {
    reject("headroom " + num(o.headroom) + " must be a number >= 1");
  }
  const ControlOptions& c = o.control;
  if (c.horizon < 1 || c.horizon > model.train_steps) {
    reject("control horizon " + std::to_string(c.horizon) + " must be in 1 .. N_train " +
           std::to_string(model.train_steps) + " (the steps the model was trained to predict)");
  }
  if (c.epochs < 1) reject("control epochs " + std::to_string(c.epochs) + " must be >= 1");
  if (c.truncation && *c.truncation < 1) {
    reject("control truncation " + std::to_string(*c.truncation) + " must be >= 1");
  }
  if (c.alphas.empty() || c.alphas.size() > 64) reject("give 1 to 64 control alphas");
  for (const double a : c.alphas) {
    if (!std::isfinite(a) || a <= 0) reject("control alpha " + num(a) + " is not positive");
    if (!(static_cast<float>(a) > 0) || !std::isfinite(static_cast<float>(a))) {
      reject("control alpha " + num(a) + " is not representable in float32");
    }
  }
  const std::pair<const char*, double> weights[] = {{"beta", c.beta}, {"w2", c.w2}, {"w3", c.w3}};
  for (const auto& [name, w] : weights) {
    if (c.physical_units) {
      if (!std::isfinite(w) || w < 0) reject(std::string("loss weight ") + name + " = " + num(w) + " must be >= 0");
      continue;
    }
    if (!std::isfinite(w) || w < 0 || w > kMaxLossWeight) {
      reject(std::string("loss weight ") + name + " = " + num(w) + " must be in [0, " +
             num(kMaxLossWeight) + "] (Q" + std::to_string(kFracLossW) + ")");
    }
  }
  loss_classes(model, c);
  active_commands(model, c);
}

void check_model(const HadynetModel& model) {
  try {
    model.check_consistent();
  } catch (const std::invalid_argument& e) {
    reject(e.what());
  }
  const trainer::HadynetDims& d = model.params.dims;
  const std::pair<const char*, int> dims[] = {
      {"x", d.x}, {"u", d.u}, {"y", d.y}, {"pb", d.pb}, {"hidden", d.hidden}};
  for (const auto& [name, v] : dims)
    if (v < 1) reject(std::string("dimension ") + name + " = " + std::to_string(v) + " < 1");
  if (d.states < 0) reject("negative number of PB states");
  if (model.train_steps < 1) reject("N_train < 1");
  for (const auto& t : model.params.tensors()) {
    for (int i = 0; i < t.size(); ++i) {
      if (!std::isfinite(t.data[i])) {
        reject("tensor '" + std::string(t.name) + "' holds a non-finite value at flat index " +
               std::to_string(i));
      }
    }
  }
  const trainer::ChannelScaling* scalings[] = {&model.norm.x, &model.norm.u, &model.norm.y};
  for (const trainer::ChannelScaling* s : scalings) {
    for (Eigen::Index i = 0; i < s->mean.size(); ++i) {
      const float mean = static_cast<float>(s->mean(i));
      const float sd = static_cast<float>(s->std(i));
      const float inv = static_cast<float>(1.0 / s->std(i));
      if (!std::isfinite(mean) || !std::isfinite(sd) || !std::isfinite(inv) || !(sd > 0) ||
          !(inv > 0)) {
        reject("a standardisation mean or std is not a finite positive float32");
      }
    }
  }
  if (!model.ranges) {
    reject("the model file holds no measured value ranges: store them with `hadynet measure-ranges "
           "MODEL LOGS` (or `hadynet-codegen measure-ranges MODEL LOGS`), or give codegen --logs");
  }
  // Stale ranges: the weights' maxima must be those the ranges were measured with.
  const trainer::ValueRanges& r = *model.ranges;
  const trainer::FoldedEncoder enc = trainer::fold_batch_norm(model.params);
  const double now[] = {max_abs(enc.weight),
                        std::max(max_abs(model.params.lstm_weight_ih),
                                 max_abs(model.params.lstm_weight_hh)),
                        max_abs(model.params.dec_weight)};
  const double stored[] = {r.enc_weight, r.lstm_weight, r.dec_weight};
  for (int i = 0; i < 3; ++i) {
    if (std::abs(now[i] - stored[i]) > 1e-6 * std::max(1.0, now[i])) {
      reject("the stored value ranges were measured with other weights (max |weight| " +
             num(stored[i]) + ", now " + num(now[i]) + "): run `hadynet measure-ranges` again");
    }
  }
  if (model.detection) {
    const trainer::DetectionCalibration& c = *model.detection;
    if (c.steps < 1 || c.steps > model.train_steps) {
      reject("detection N_detect " + std::to_string(c.steps) + " must be in 1 .. N_train " +
             std::to_string(model.train_steps));
    }
    if (!c.pb.allFinite() || !c.mean.allFinite() || !c.inverse.allFinite() ||
        !std::isfinite(c.threshold) || !(c.threshold > 0)) {
      reject("detection statistics are not finite (or the threshold is not positive)");
    }
  }
}

std::string format_line(const char* name, const FormatChoice& f) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "//   %-13s = %2d  ", name, f.frac);
  return comment_lines(buf, comment_text(f.from), "//                       ");
}

// ---- header sections ---------------------------------------------------------

struct Emitter {
  std::string out;

  void line(const std::string& s = "") {
    out += s;
    out += '\n';
  }
  void member(const std::string& type, const std::string& name, const std::string& value,
              const std::string& comment = "") {
    line("  static constexpr " + type + " " + name + " = " + value + ";" +
         (comment.empty() ? "" : "  // " + comment));
  }
  void array1(const std::string& type, const std::string& decl,
              const std::vector<std::string>& items) {
    line("  static constexpr " + type + " " + decl + " = {");
    line("      " + wrapped(items, 6, 6) + "};");
  }
  void array2(const std::string& type, const std::string& decl,
              const std::vector<std::vector<std::string>>& rows) {
    line("  static constexpr " + type + " " + decl + " = {");
    for (const auto& row : rows) line("      {" + wrapped(row, 7, 7) + "},");
    line("  };");
  }
};

std::vector<std::string> float_items(const Eigen::VectorXd& v) {
  std::vector<std::string> items;
  for (Eigen::Index i = 0; i < v.size(); ++i) items.push_back(float_literal(static_cast<float>(v(i))));
  return items;
}

// 1 / std in double, rounded once to float.
std::vector<std::string> inv_items(const Eigen::VectorXd& stds) {
  std::vector<std::string> items;
  for (Eigen::Index i = 0; i < stds.size(); ++i)
    items.push_back(float_literal(static_cast<float>(1.0 / stds(i))));
  return items;
}

std::vector<std::string> string_items(const std::vector<std::string>& v) {
  std::vector<std::string> items;
  for (const std::string& s : v) items.push_back(string_literal(s));
  return items;
}

// Values of a tensor as literals in the header's numeric: q15 quantised to
// Q(frac) (int32 when `bias`), f32 as float. `get(r, c)` is the real value (a
// float tensor's value widened, or a double statistic).
struct TensorWriter {
  Numeric numeric;
  std::vector<std::string> report;  // quantisation error lines

  template <class Get>
  std::vector<std::vector<std::string>> rows(const std::string& name, Eigen::Index n_rows,
                                             Eigen::Index n_cols, int frac, bool bias, Get get) {
    Quantiser q{frac, bias, name, 0.0};
    std::vector<std::vector<std::string>> out(static_cast<std::size_t>(n_rows));
    for (Eigen::Index r = 0; r < n_rows; ++r) {
      for (Eigen::Index c = 0; c < n_cols; ++c) {
        const double v = get(r, c);
        if (numeric == Numeric::kQ15) {
          out[static_cast<std::size_t>(r)].push_back(
              std::to_string(q(v, n_cols == 1 ? index_text(r) : index_text(r, c))));
        } else {
          out[static_cast<std::size_t>(r)].push_back(float_literal(static_cast<float>(v)));
        }
      }
    }
    if (numeric == Numeric::kQ15) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "//   %-16s Q%-2d  %.3g (%.3f LSB)", name.c_str(), frac,
                    q.max_error, std::ldexp(q.max_error, frac));
      report.push_back(buf);
    }
    return out;
  }
  template <class Get>
  std::vector<std::string> vector(const std::string& name, Eigen::Index n, int frac, bool bias,
                                  Get get) {
    std::vector<std::string> flat;
    for (auto& row : rows(name, n, 1, frac, bias, [&](Eigen::Index r, Eigen::Index) { return get(r); }))
      flat.push_back(row.front());
    return flat;
  }
};

// The command-line options that reproduce `o`, one string per option.
std::vector<std::string> option_words(const CodegenOptions& o) {
  std::string alphas;
  for (std::size_t i = 0; i < o.control.alphas.size(); ++i)
    alphas += (i ? "," : "") + exact_num(o.control.alphas[i]);
  std::string commands;
  const std::vector<std::string>& names = o.control.commands.value();
  for (std::size_t i = 0; i < names.size(); ++i) commands += (i ? "," : "") + names[i];
  return {"--numeric " + std::string(numeric_name(o.numeric)),
          "--namespace " + namespace_of(o),
          "--headroom " + exact_num(o.headroom),
          "--control-horizon " + std::to_string(o.control.horizon),
          "--control-epochs " + std::to_string(o.control.epochs),
          "--control-alphas " + alphas,
          "--control-truncation " + std::to_string(o.control.truncation.value_or(o.control.horizon)),
          "--beta " + exact_num(o.control.beta),
          "--w2 " + exact_num(o.control.w2),
          "--w3 " + exact_num(o.control.w3),
          std::string("--loss-units ") + (o.control.physical_units ? "physical" : "standardised"),
          "--control-commands " + (names.empty() ? std::string("all") : commands)};
}

}  // namespace

// ---- public ----------------------------------------------------------------

std::string namespace_of(const CodegenOptions& options) {
  if (!options.ns.empty()) return options.ns;
  return std::string("hadynet::model_") + numeric_name(options.numeric);
}

std::string header_file_name(Numeric numeric) {
  return std::string("hadynet_model_") + numeric_name(numeric) + ".h";
}

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

Eigen::MatrixXd whitening_matrix(const Eigen::MatrixXd& inverse) {
  if (inverse.rows() != inverse.cols() || inverse.rows() == 0) {
    reject("detection inverse covariance is not a non-empty square matrix");
  }
  if (!inverse.allFinite()) reject("detection inverse covariance is not finite");
  const double scale = inverse.cwiseAbs().maxCoeff();
  if ((inverse - inverse.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) {
    reject("detection inverse covariance is not symmetric");
  }
  const Eigen::MatrixXd sym = 0.5 * (inverse + inverse.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(sym);
  if (eig.info() != Eigen::Success) reject("eigendecomposition of the detection inverse failed");
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  if (!(lambda.minCoeff() > 0)) {
    reject("detection inverse covariance is not positive definite (smallest eigenvalue " +
           num(lambda.minCoeff()) + ")");
  }
  Eigen::MatrixXd v = eig.eigenvectors();
  for (Eigen::Index k = 0; k < v.cols(); ++k) {
    Eigen::Index arg = 0;
    v.col(k).cwiseAbs().maxCoeff(&arg);
    if (v(arg, k) < 0) v.col(k) = -v.col(k);
  }
  return lambda.cwiseSqrt().asDiagonal() * v.transpose();
}

Formats choose_formats(const HadynetModel& model, const CodegenOptions& options) {
  check_model(model);
  check_options(model, options);
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

  const trainer::FoldedEncoder enc = trainer::fold_batch_norm(model.params);
  const double enc_w = max_abs(enc.weight);
  f.enc_w = pick(enc_w, "kFracEncW (folded encoder weight)", "m " + num(enc_w) + " = |folded encoder weight|");
  const double lstm_w =
      std::max(max_abs(model.params.lstm_weight_ih), max_abs(model.params.lstm_weight_hh));
  f.lstm_w = pick(lstm_w, "kFracLstmW (LSTM weights)", "m " + num(lstm_w) + " = max |W_ih|, |W_hh|");
  f.lstm_acc = {f.lstm_w.frac + std::max(f.in.frac, f.h.frac), 0.0,
                "kFracLstmW + max(kFracIn, kFracH) (int32 LSTM bias format)"};
  const double dec_w = max_abs(model.params.dec_weight);
  f.dec_w = pick(dec_w, "kFracDecW (decoder weight)", "m " + num(dec_w) + " = |decoder weight|");

  if (model.detection) {
    const double w = max_abs(whitening_matrix(model.detection->inverse));
    f.whiten = pick(w, "kFracWhiten (detection whitening)", "m " + num(w) + " = |W|, W^T W = Sigma_e^-1");
    const double z = kZBoundFactor * model.detection->threshold;
    f.z = pick(z, "kFracZ (whitened error)",
               "m " + num(z) + " = 4 x C_detect " + num(model.detection->threshold));
  } else {
    f.whiten = {15, 0.0, "no detection calibration"};
    f.z = {15, 0.0, "no detection calibration"};
  }
  if (options.control.physical_units) {
    f.loss_w = pick(1.0, "kFracLossW (loss weights)", "m 1 = the largest weight (physical units, normalised)");
  } else {
    f.loss_w = {kFracLossW, 0.0, "fixed: loss weights up to 7.99 (standardised units)"};
  }
  return f;
}

GeneratedHeader generate(const HadynetModel& model, const ModelIdentity& identity,
                         const CodegenOptions& given) {
  const CodegenOptions options = with_profile(given, model);
  const Formats f = choose_formats(model, options);
  const bool q15 = options.numeric == Numeric::kQ15;
  const trainer::HadynetDims& d = model.params.dims;
  const trainer::ValueRanges& r = *model.ranges;
  const trainer::FoldedEncoder enc = trainer::fold_batch_norm(model.params);
  const ControlOptions& ctl = options.control;
  const std::string ns = namespace_of(options);
  const std::vector<firmware::LossClass> classes = loss_classes(model, ctl);
  const int pb_rows = std::max(d.states, 1);

  // All values first (this is where quantisation can still reject the model).
  TensorWriter tw{options.numeric, {}};
  const auto enc_w = tw.rows("kEncWeight", d.hidden, d.x + d.pb, f.enc_w.frac, false,
                             [&](Eigen::Index i, Eigen::Index j) { return double{enc.weight(i, j)}; });
  const auto enc_b = tw.vector("kEncBias", d.hidden, f.enc_w.frac + f.in.frac, true,
                               [&](Eigen::Index i) { return double{enc.bias(i)}; });
  const auto lstm_ih = tw.rows("kLstmWeightIh", 4 * d.hidden, d.u + d.pb, f.lstm_w.frac, false,
                               [&](Eigen::Index i, Eigen::Index j) {
                                 return double{model.params.lstm_weight_ih(i, j)};
                               });
  const auto lstm_hh = tw.rows("kLstmWeightHh", 4 * d.hidden, d.hidden, f.lstm_w.frac, false,
                               [&](Eigen::Index i, Eigen::Index j) {
                                 return double{model.params.lstm_weight_hh(i, j)};
                               });
  // b_ih + b_hh in double (exact for all but extreme exponent differences), rounded once.
  const auto lstm_b = tw.vector("kLstmBias", 4 * d.hidden, f.lstm_acc.frac, true, [&](Eigen::Index i) {
    return double{model.params.lstm_bias_ih(i)} + double{model.params.lstm_bias_hh(i)};
  });
  const auto dec_w = tw.rows("kDecWeight", d.y, d.hidden, f.dec_w.frac, false,
                             [&](Eigen::Index i, Eigen::Index j) { return double{model.params.dec_weight(i, j)}; });
  const auto dec_b = tw.vector("kDecBias", d.y, f.dec_w.frac + f.h.frac, true,
                               [&](Eigen::Index i) { return double{model.params.dec_bias(i)}; });
  const auto pb_table = tw.rows("kPbTable", pb_rows, d.pb, f.in.frac, false,
                                [&](Eigen::Index i, Eigen::Index j) {
                                  return d.states > 0 ? double{model.params.pb(i, j)} : 0.0;
                                });
  const trainer::DetectionCalibration* det = model.detection ? &*model.detection : nullptr;
  const Eigen::MatrixXd whiten =
      det ? whitening_matrix(det->inverse) : Eigen::MatrixXd::Zero(d.y, d.y);
  const auto det_pb = tw.vector("kDetectPb", d.pb, f.in.frac, false,
                                [&](Eigen::Index i) { return det ? det->pb(i) : 0.0; });
  const auto det_mean = tw.vector("kDetectMean", d.y, f.y.frac, false,
                                  [&](Eigen::Index i) { return det ? det->mean(i) : 0.0; });
  const auto det_whiten = tw.rows("kDetectWhiten", d.y, d.y, f.whiten.frac, false,
                                  [&](Eigen::Index i, Eigen::Index j) { return whiten(i, j); });
  const auto alphas = tw.vector("kControlAlpha", static_cast<Eigen::Index>(ctl.alphas.size()),
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
  const auto class_weight = [&](firmware::LossClass c, bool up) {
    switch (c) {
      case firmware::LossClass::kForce: return up ? 1.0 : ctl.beta;
      case firmware::LossClass::kAngle: return ctl.w2;
      case firmware::LossClass::kLength: return ctl.w3;
      case firmware::LossClass::kNone: break;
    }
    return 0.0;
  };
  // Physical units: w std^2, scaled so that the largest weight is 1.
  double loss_scale = 1.0;
  if (ctl.physical_units) {
    double largest = 0.0;
    for (Eigen::Index i = 0; i < d.y; ++i) {
      const double s2 = model.norm.y.std(i) * model.norm.y.std(i);
      for (bool up : {true, false})
        largest = std::max(largest, class_weight(classes[static_cast<std::size_t>(i)], up) * s2);
    }
    if (!(largest > 0)) reject("every loss weight is zero: the stabiliser would have nothing to minimise");
    loss_scale = 1.0 / largest;
  }
  const auto weight_of = [&](Eigen::Index i, bool up) {
    const double s2 = ctl.physical_units ? model.norm.y.std(i) * model.norm.y.std(i) : 1.0;
    return class_weight(classes[static_cast<std::size_t>(i)], up) * s2 * loss_scale;
  };
  const auto loss_up = tw.vector("kLossWeightUp", d.y, f.loss_w.frac, false,
                                 [&](Eigen::Index i) { return weight_of(i, true); });
  const auto loss_down = tw.vector("kLossWeightDown", d.y, f.loss_w.frac, false,
                                   [&](Eigen::Index i) { return weight_of(i, false); });
  const std::vector<bool> active = active_commands(model, ctl);
  const SensorArrays sensor = sensor_arrays(model, q15, f.y.frac);
  std::string threshold_sq;
  const double threshold = det ? det->threshold : 0.0;
  if (q15) {
    threshold_sq = std::to_string(to_fixed(threshold * threshold, 2 * f.z.frac));
  } else {
    threshold_sq = float_literal(static_cast<float>(threshold * threshold));
  }

  // ---- the text
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
    for (const std::string& l : tw.report) e.line(l);
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
  e.line();
  e.line("  // ---- network (standardised units)");
  e.line("  // h_0 = ReLU(kEncWeight [x ; p] + kEncBias), batch norm folded in; gate order i, f, g, o.");
  e.array2("Value", "kEncWeight[kHidden][kX + kPb]", enc_w);
  e.array1("Bias", "kEncBias[kHidden]", enc_b);
  e.array2("Value", "kLstmWeightIh[4 * kHidden][kU + kPb]", lstm_ih);
  e.array2("Value", "kLstmWeightHh[4 * kHidden][kHidden]", lstm_hh);
  e.array1("Bias", "kLstmBias[4 * kHidden]", lstm_b);
  e.array2("Value", "kDecWeight[kY][kHidden]", dec_w);
  e.array1("Bias", "kDecBias[kY]", dec_b);
  e.line();
  e.line("  // ---- PB table (Q(kFracIn) or float), one row per dynamics state");
  e.array2("Value", "kPbTable[kPbRows][kPb]", pb_table);
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
  e.array1("Value", "kDetectPb[kPb]", det_pb);
  e.array1("Value", "kDetectMean[kY]", det_mean);
  e.array2("Value", "kDetectWhiten[kY][kY]", det_whiten);
  e.member("float", "kDetectThreshold", float_literal(static_cast<float>(threshold)));
  e.member(q15 ? "std::int64_t" : "float", "kDetectThresholdSq", threshold_sq,
           q15 ? "C_detect^2 in Q(2 kFracZ)" : "C_detect^2");
  e.line();
  e.line("  // ---- grasp stabiliser");
  e.member("int", "kControlHorizon", std::to_string(ctl.horizon));
  e.member("int", "kControlEpochs", std::to_string(ctl.epochs));
  e.member("int", "kControlAlphaCount", std::to_string(ctl.alphas.size()));
  e.member("int", "kControlTruncation", std::to_string(ctl.truncation.value_or(ctl.horizon)),
           ctl.truncation.value_or(ctl.horizon) >= ctl.horizon ? "full BPTT" : "truncated");
  e.array1("Value", "kControlAlpha[kControlAlphaCount]", alphas);
  items.clear();
  for (const firmware::LossClass c : classes) {
    switch (c) {
      case firmware::LossClass::kForce: items.push_back("hadynet::firmware::LossClass::kForce"); break;
      case firmware::LossClass::kAngle: items.push_back("hadynet::firmware::LossClass::kAngle"); break;
      case firmware::LossClass::kLength: items.push_back("hadynet::firmware::LossClass::kLength"); break;
      case firmware::LossClass::kNone: items.push_back("hadynet::firmware::LossClass::kNone"); break;
    }
  }
  e.array1("hadynet::firmware::LossClass", "kLossClass[kY]", items);
  e.array1("Value", "kLossWeightUp[kY]", loss_up);
  e.array1("Value", "kLossWeightDown[kY]", loss_down);
  items.clear();
  for (const bool a : active) items.push_back(a ? "true" : "false");
  e.array1("bool", "kControlActive[kU]", items);
  e.line();
  e.line("  // ---- derived inputs: computed by the firmware from their base command");
  e.array1("hadynet::firmware::DerivedKind", "kUDerived[kU]", sensor.derived);
  e.array1("int", "kUDerivedBase[kU]", sensor.derived_base);
  e.line();
  e.line("  // ---- sensor model: measured y_c = clip(y'_c + sum gain y'_source + rate D_c)");
  for (const std::string& l : sensor.notes) e.line("  // " + l);
  e.member("int", "kCrosstalkCount", std::to_string(sensor.crosstalk_count));
  e.array1("int", "kCrosstalkTarget[" + std::to_string(sensor.crosstalk_target.size()) + "]", sensor.crosstalk_target);
  e.array1("int", "kCrosstalkSource[" + std::to_string(sensor.crosstalk_source.size()) + "]", sensor.crosstalk_source);
  e.array1("float", "kCrosstalkGain[" + std::to_string(sensor.crosstalk_gain.size()) + "]", sensor.crosstalk_gain);
  e.member("int", "kDriftCount", std::to_string(sensor.drift_count));
  e.array1("int", "kDriftChannel[" + std::to_string(sensor.drift_channel.size()) + "]", sensor.drift_channel);
  e.array1("bool", "kDriftIsLoad[" + std::to_string(sensor.drift_is_load.size()) + "]", sensor.drift_is_load);
  e.array1("float", "kDriftRate[" + std::to_string(sensor.drift_rate.size()) + "]", sensor.drift_rate);
  e.member("float", "kSensorPeriod", sensor.period, "s per frame (drift integration)");
  e.member("int", "kClipCount", std::to_string(sensor.clip_count));
  e.array1("int", "kClipChannel[" + std::to_string(sensor.clip_channel.size()) + "]", sensor.clip_channel);
  e.array1("int", "kClipSide[" + std::to_string(sensor.clip_side.size()) + "]", sensor.clip_side);
  e.array1("float", "kClipRail[" + std::to_string(sensor.clip_rail.size()) + "]", sensor.clip_rail);
  e.array1("Value", "kClipRailModel[" + std::to_string(sensor.clip_rail_model.size()) + "]", sensor.clip_rail_model);
  e.line("};");
  e.line();
  e.line("static_assert(hadynet::firmware::GeneratedModel<Model>);");
  e.line();
  e.line("}  // namespace " + ns);
  e.line();
  e.line("#endif  // " + guard);
  return {file_name, std::move(e.out), f};
}

LoadedModel load_model_file(const std::string& path) {
  std::string bytes;
  trainer::safetensors::File file;
  try {
    bytes = trainer::safetensors::read_bytes(path);
    file = trainer::safetensors::parse(bytes, path);
  } catch (const trainer::safetensors::FormatError& e) {
    throw trainer::ModelFileError(e.what());
  }
  LoadedModel loaded{trainer::model_from_safetensors(file, path), {}};
  loaded.identity.file_name = fs::path(path).filename().string();
  loaded.identity.hash = datalog::fnv1a64(bytes);
  return loaded;
}

WriteResult write_header(const std::string& dir, const GeneratedHeader& header) {
  const fs::path path = fs::path(dir) / header.file_name;
  WriteResult result{path.string(), false};
  {
    std::ifstream old(path, std::ios::binary);
    if (old) {
      const std::string text{std::istreambuf_iterator<char>(old), std::istreambuf_iterator<char>()};
      if (text == header.text) return result;
    }
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create the directory: " + ec.message());
  try {
    datalog::write_file_atomically(path, header.text);
  } catch (const datalog::AtomicWriteError& e) {
    throw std::runtime_error(std::string("cannot write the generated header: ") + e.what());
  }
  result.changed = true;
  return result;
}

}  // namespace hadynet::codegen
