#include "codegen/shape_id.h"

#include "datalog/content_hash.h"

namespace hadynet::codegen {

const std::set<std::string>& data_members() {
  static const std::set<std::string> names = {
      "kXMean",         "kXInvStd",       "kUMean",         "kUStd",          "kUInvStd",
      "kYMean",         "kYStd",          "kYInvStd",       "kEncWeight",     "kEncBias",
      "kLstmWeightIh",  "kLstmWeightHh",  "kLstmBias",      "kDecWeight",     "kDecBias",
      "kPbTable",       "kStateNames",    "kStateObjects",  "kDetectPb",      "kDetectMean",
      "kDetectWhiten",  "kDetectThreshold", "kDetectThresholdSq", "kControlAlpha", "kLossWeightUp",
      "kLossWeightDown", "kCrosstalkGain", "kDriftRate",    "kClipRail",      "kClipRailModel",
      "kCurveLevel",    "kCurveReading"};
  return names;
}

const std::set<std::string>& identity_members() {
  static const std::set<std::string> names = {"kGeneratorVersion", "kModelHash", "kShapeId"};
  return names;
}

std::uint64_t shape_id(const std::map<std::string, std::vector<std::string>>& literals) {
  datalog::Fnv1a64 h;
  for (const auto& [name, items] : literals) {
    if (data_members().count(name) != 0 || identity_members().count(name) != 0) continue;
    h.update(name);
    h.update("=");
    for (std::size_t i = 0; i < items.size(); ++i) {
      if (i != 0) h.update(",");
      h.update(items[i]);
    }
    h.update(";");
  }
  return h.value();
}

}  // namespace hadynet::codegen
