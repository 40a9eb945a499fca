#include "codegen/checks.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <stdexcept>
#include <utility>

#include "codegen/codegen.h"
#include "codegen/header_text.h"
#include "codegen/unsupported_model.h"
#include "trainer/derived_inputs.h"

namespace hadynet::codegen {

using trainer::HadynetModel;

namespace {

template <class M>
double max_abs(const M& m) {
  return m.size() == 0 ? 0.0 : static_cast<double>(m.cwiseAbs().maxCoeff());
}

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

}  // namespace

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
           "MODEL LOGS` (or `hadynet-measure-ranges MODEL LOGS`), or give `hadynet codegen` --logs");
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

void check_stored_ranges(const HadynetModel& model, const trainer::FoldedEncoder& enc) {
  const trainer::ValueRanges& r = *model.ranges;
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
}

void check_options(const HadynetModel& model, const CodegenOptions& o) {
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
  const std::pair<const char*, double> weights[] = {{"beta", c.loss.beta}, {"w2", c.loss.w2}, {"w3", c.loss.w3}};
  for (const auto& [name, w] : weights) {
    if (c.loss.physical_units) {
      if (!std::isfinite(w) || w < 0) reject(std::string("loss weight ") + name + " = " + num(w) + " must be >= 0");
      continue;
    }
    if (!std::isfinite(w) || w < 0 || w > kMaxLossWeight) {
      reject(std::string("loss weight ") + name + " = " + num(w) + " must be in [0, " +
             num(kMaxLossWeight) + "] (Q" + std::to_string(kFracLossW) + ")");
    }
  }
}

std::vector<bool> active_commands(const HadynetModel& model, const ControlOptions& c) {
  const std::vector<std::string>& u = model.layout.u_names;
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

}  // namespace hadynet::codegen
