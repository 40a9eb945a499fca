// A generated header's data members as run-time arrays of a firmware's
// shape M: the source build_tensors<M> (firmware/core/model_tensors.h)
// reads for a model image, filled from the literals codegen wrote for the
// new model (codegen::GeneratedHeader::literals). The literals are the
// header's own text, read back exactly (integers for q15, float literals
// that round-trip for f32), so an image's tensors are bit for bit what a
// firmware compiled from that header would hold (test: model_image_test).
#pragma once

#include <charconv>
#include <limits>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "firmware/core/model_contract.h"

namespace hadynet::host {

// Thrown when a literal is missing, of the wrong count or not a number.
class ModelLiteralError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using Literals = std::map<std::string, std::vector<std::string>>;

namespace detail {

inline const std::vector<std::string>& items_of(const Literals& literals, const std::string& name,
                                                std::size_t count) {
  const auto it = literals.find(name);
  if (it == literals.end()) throw ModelLiteralError("model image: the generated header has no " + name);
  if (it->second.size() != count) {
    throw ModelLiteralError("model image: " + name + " has " + std::to_string(it->second.size()) +
                            " values, the firmware's shape " + std::to_string(count));
  }
  return it->second;
}

// One literal as T: integers exactly (q15 values, biases, int64), floats by
// strtof of the float literal (the 'f' suffix dropped), strings unquoted.
template <class T>
T parse_literal(const std::string& name, const std::string& text) {
  if constexpr (std::is_same_v<T, float>) {
    std::string s = text;
    if (!s.empty() && s.back() == 'f') s.pop_back();
    char* end = nullptr;
    const float v = std::strtof(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size()) throw ModelLiteralError("model image: " + name + ": bad float " + text);
    return v;
  } else {
    static_assert(std::is_integral_v<T>);
    if constexpr (std::is_same_v<T, std::uint64_t>) {  // a hash: "0x0123456789abcdefULL"
      std::uint64_t v = 0;
      const bool hex = text.size() == 21 && text.rfind("0x", 0) == 0 && text.compare(18, 3, "ULL") == 0;
      const auto [ptr, ec] = hex ? std::from_chars(text.data() + 2, text.data() + 18, v, 16)
                                 : std::from_chars_result{text.data(), std::errc::invalid_argument};
      if (!hex || ec != std::errc() || ptr != text.data() + 18)
        throw ModelLiteralError("model image: " + name + ": bad hash " + text);
      return v;
    } else {
      std::int64_t v = 0;
      const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
      if (ec != std::errc() || ptr != text.data() + text.size() || v < std::numeric_limits<T>::min() ||
          v > std::numeric_limits<T>::max()) {
        throw ModelLiteralError("model image: " + name + ": bad integer " + text);
      }
      return static_cast<T>(v);
    }
  }
}

// A C++ string literal written by codegen::string_literal, unquoted
// (escapes: \" \\ and three-digit octal).
inline std::string unquote(const std::string& name, const std::string& text) {
  if (text.size() < 2 || text.front() != '"' || text.back() != '"')
    throw ModelLiteralError("model image: " + name + ": bad string " + text);
  std::string out;
  for (std::size_t i = 1; i + 1 < text.size(); ++i) {
    if (text[i] != '\\') {
      out += text[i];
    } else if (i + 1 < text.size() - 1 && (text[i + 1] == '"' || text[i + 1] == '\\')) {
      out += text[++i];
    } else if (i + 3 < text.size() - 1) {
      out += static_cast<char>(std::stoi(text.substr(i + 1, 3), nullptr, 8));
      i += 3;
    } else {
      throw ModelLiteralError("model image: " + name + ": bad escape in " + text);
    }
  }
  return out;
}

template <class T, std::size_t N>
void fill(const Literals& l, const std::string& name, T (&out)[N]) {
  const auto& items = items_of(l, name, N);
  for (std::size_t i = 0; i < N; ++i) out[i] = parse_literal<T>(name, items[i]);
}
template <class T, std::size_t R, std::size_t C>
void fill(const Literals& l, const std::string& name, T (&out)[R][C]) {
  const auto& items = items_of(l, name, R * C);
  for (std::size_t r = 0; r < R; ++r)
    for (std::size_t c = 0; c < C; ++c) out[r][c] = parse_literal<T>(name, items[r * C + c]);
}
template <class T>
void fill_scalar(const Literals& l, const std::string& name, T& out) {
  out = parse_literal<T>(name, items_of(l, name, 1)[0]);
}

}  // namespace detail

// The data members of a generated header of shape M, by the header's names
// (model_contract.h), as build_tensors<M> reads them.
template <firmware::GeneratedModel M>
struct RowMajorModel {
  using Value = typename M::Value;
  using Bias = typename M::Bias;
  using ThresholdSq = std::remove_cv_t<decltype(M::kDetectThresholdSq)>;
  static constexpr int kPbRows = M::kStates > 0 ? M::kStates : 1;
  static constexpr int kCrosstalks = M::kCrosstalkCount > 0 ? M::kCrosstalkCount : 1;
  static constexpr int kDrifts = M::kDriftCount > 0 ? M::kDriftCount : 1;
  static constexpr int kClips = M::kClipCount > 0 ? M::kClipCount : 1;
  static constexpr int kCurveValues = (M::kCurveCount > 0 ? M::kCurveCount : 1) * M::kCurveKnots;

  std::uint64_t kModelHash;
  float kXMean[M::kX], kXInvStd[M::kX];
  float kUMean[M::kU], kUStd[M::kU], kUInvStd[M::kU];
  float kYMean[M::kY], kYStd[M::kY], kYInvStd[M::kY];
  Value kEncWeight[M::kHidden][M::kX + M::kPb];
  Bias kEncBias[M::kHidden];
  Value kLstmWeightIh[4 * M::kHidden][M::kU + M::kPb];
  Value kLstmWeightHh[4 * M::kHidden][M::kHidden];
  Bias kLstmBias[4 * M::kHidden];
  Value kDecWeight[M::kY][M::kHidden];
  Bias kDecBias[M::kY];
  Value kPbTable[kPbRows][M::kPb];
  std::string state_names[kPbRows];
  const char* kStateNames[kPbRows];  // into state_names
  Value kDetectPb[M::kPb];
  Value kDetectMean[M::kY];
  Value kDetectWhiten[M::kY][M::kY];
  float kDetectThreshold;
  ThresholdSq kDetectThresholdSq;
  Value kControlAlpha[M::kControlAlphaCount];
  Value kLossWeightUp[M::kY];
  Value kLossWeightDown[M::kY];
  float kCrosstalkGain[kCrosstalks];
  float kDriftRate[kDrifts];
  float kClipRail[kClips];
  Value kClipRailModel[kClips];
  float kCurveLevel[kCurveValues];
  float kCurveReading[kCurveValues];

  RowMajorModel() = default;
  RowMajorModel(const RowMajorModel&) = delete;  // kStateNames points into this object
  RowMajorModel& operator=(const RowMajorModel&) = delete;

  // Every data member from `literals` (ModelLiteralError naming the member
  // that is missing, of another size or not a number).
  void read(const Literals& l) {
    using detail::fill;
    detail::fill_scalar(l, "kModelHash", kModelHash);
    fill(l, "kXMean", kXMean);
    fill(l, "kXInvStd", kXInvStd);
    fill(l, "kUMean", kUMean);
    fill(l, "kUStd", kUStd);
    fill(l, "kUInvStd", kUInvStd);
    fill(l, "kYMean", kYMean);
    fill(l, "kYStd", kYStd);
    fill(l, "kYInvStd", kYInvStd);
    fill(l, "kEncWeight", kEncWeight);
    fill(l, "kEncBias", kEncBias);
    fill(l, "kLstmWeightIh", kLstmWeightIh);
    fill(l, "kLstmWeightHh", kLstmWeightHh);
    fill(l, "kLstmBias", kLstmBias);
    fill(l, "kDecWeight", kDecWeight);
    fill(l, "kDecBias", kDecBias);
    fill(l, "kPbTable", kPbTable);
    const auto& names = detail::items_of(l, "kStateNames", kPbRows);
    for (int r = 0; r < kPbRows; ++r) {
      state_names[r] = detail::unquote("kStateNames", names[static_cast<std::size_t>(r)]);
      kStateNames[r] = state_names[r].c_str();
    }
    fill(l, "kDetectPb", kDetectPb);
    fill(l, "kDetectMean", kDetectMean);
    fill(l, "kDetectWhiten", kDetectWhiten);
    detail::fill_scalar(l, "kDetectThreshold", kDetectThreshold);
    detail::fill_scalar(l, "kDetectThresholdSq", kDetectThresholdSq);
    fill(l, "kControlAlpha", kControlAlpha);
    fill(l, "kLossWeightUp", kLossWeightUp);
    fill(l, "kLossWeightDown", kLossWeightDown);
    fill(l, "kCrosstalkGain", kCrosstalkGain);
    fill(l, "kDriftRate", kDriftRate);
    fill(l, "kClipRail", kClipRail);
    fill(l, "kClipRailModel", kClipRailModel);
    fill(l, "kCurveLevel", kCurveLevel);
    fill(l, "kCurveReading", kCurveReading);
  }
};

}  // namespace hadynet::host
