// The build's generated model headers (codegen of HADYNET_MODEL, see
// cmake/hadynet_model.cmake) against the model file loaded with the trainer:
// dimensions, channels, standardisation, every weight, the PB table, the
// detection statistics, the control constants, the formats and the hash.
// Expected values come from the trainer's model and fixed_point.h's
// real_to_fixed, never from the generator; each check states its tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>

#include "codegen/codegen.h"
#include "firmware/core/fixed_point.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "trainer/deploy_prep.h"
#include "trainer/log_dataset.h"
#include "trainer/model_file.h"

namespace {

using Q = hadynet::model_q15::Model;
using F = hadynet::model_f32::Model;
using hadynet::firmware::LossClass;
using hadynet::trainer::HadynetModel;
namespace fixed = hadynet::fixed;

const HadynetModel& model() {
  static const HadynetModel m = hadynet::trainer::load_model(HADYNET_MODEL_PATH);
  return m;
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool same_bits(float a, float b) {
  return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}

// Half an LSB of Q(frac): the bound of round-to-nearest.
double half_lsb(int frac) { return std::ldexp(0.5, -frac); }

// q15 tensor vs real values: count of entries differing from
// real_to_fixed<Int, Frac>(real) (must be 0: exact), largest dequantisation
// error in LSB (<= 0.5: rounding to nearest), largest |raw|.
struct QuantCheck {
  long mismatches = 0;
  double max_error_lsb = 0;
  long max_raw = 0;
};
template <class Int, int Frac, class Raw, class Real>
QuantCheck check_q_impl(std::size_t rows, std::size_t cols, Raw raw, Real real) {
  QuantCheck c;
  for (std::size_t i = 0; i < rows; ++i) {
    for (std::size_t j = 0; j < cols; ++j) {
      const Int q = raw(i, j);
      const auto v = real(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
      if (q != fixed::real_to_fixed<Int, Frac>(v)) ++c.mismatches;
      const double err = std::abs(fixed::to_real<Frac, double>(q) - static_cast<double>(v));
      c.max_error_lsb = std::max(c.max_error_lsb, std::ldexp(err, Frac));
      c.max_raw = std::max(c.max_raw, std::abs(static_cast<long>(q)));
    }
  }
  return c;
}
template <class Int, int Frac, std::size_t R, std::size_t C, class Real>
QuantCheck check_q(const Int (&q)[R][C], Real real) {
  return check_q_impl<Int, Frac>(R, C, [&](std::size_t i, std::size_t j) { return q[i][j]; }, real);
}
template <class Int, int Frac, std::size_t N, class Real>
QuantCheck check_q(const Int (&q)[N], Real real) {
  return check_q_impl<Int, Frac>(
      N, 1, [&](std::size_t i, std::size_t) { return q[i]; },
      [&](Eigen::Index i, Eigen::Index) { return real(i); });
}
// f32 tensor vs float values: entries whose bits differ (must be 0).
template <std::size_t R, std::size_t C, class Real>
long f32_mismatches(const float (&v)[R][C], Real real) {
  long n = 0;
  for (std::size_t i = 0; i < R; ++i) {
    for (std::size_t j = 0; j < C; ++j) {
      if (!same_bits(v[i][j], real(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)))) ++n;
    }
  }
  return n;
}
template <std::size_t N, class Real>
long f32_mismatches(const float (&v)[N], Real real) {
  long n = 0;
  for (std::size_t i = 0; i < N; ++i)
    if (!same_bits(v[i], real(static_cast<Eigen::Index>(i)))) ++n;
  return n;
}

// The rule of docs/codegen.md: F is the largest frac <= 15 with
// round(m 2^F) <= 32767.
bool is_rule_format(double m, int frac) {
  const auto raw = [m](int f) { return fixed::real_to_fixed<std::int64_t, 0>(std::ldexp(m, f)); };
  return frac >= 0 && frac <= 15 && raw(frac) <= 32767 && (frac == 15 || raw(frac + 1) > 32767);
}

TEST(DefaultModel, IdentityAndHash) {
  EXPECT_EQ(Q::kContractVersion, hadynet::firmware::kModelContractVersion);
  EXPECT_EQ(F::kContractVersion, hadynet::firmware::kModelContractVersion);
  EXPECT_EQ(std::string(Q::kGeneratorVersion).rfind("hadynet-codegen ", 0), 0u);
  EXPECT_EQ(Q::kNumeric, hadynet::firmware::Numeric::kQ15);
  EXPECT_EQ(F::kNumeric, hadynet::firmware::Numeric::kF32);
  // FNV-1a 64 (offset basis 0xcbf29ce484222325, prime 0x100000001b3) of the bytes.
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const char c : file_bytes(HADYNET_MODEL_PATH)) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  EXPECT_EQ(Q::kModelHash, h);
  EXPECT_EQ(F::kModelHash, h);
}

TEST(DefaultModel, DimensionsChannelsAndStandardisation) {
  const HadynetModel& m = model();
  const auto& d = m.params.dims;
  EXPECT_EQ(Q::kX, d.x);
  EXPECT_EQ(Q::kU, d.u);
  EXPECT_EQ(Q::kY, d.y);
  EXPECT_EQ(Q::kPb, d.pb);
  EXPECT_EQ(Q::kHidden, d.hidden);
  EXPECT_EQ(Q::kStates, d.states);
  EXPECT_EQ(Q::kTrainSteps, m.train_steps);
  EXPECT_EQ(F::kX, d.x);
  EXPECT_EQ(F::kHidden, d.hidden);
  for (int i = 0; i < Q::kY; ++i) {
    EXPECT_EQ(std::string(Q::kYNames[i]), m.layout.y_names[static_cast<std::size_t>(i)]);
    // float32 of the double statistics, rounded once (exact comparison).
    EXPECT_TRUE(same_bits(Q::kYMean[i], static_cast<float>(m.norm.y.mean(i))));
    EXPECT_TRUE(same_bits(Q::kYStd[i], static_cast<float>(m.norm.y.std(i))));
    EXPECT_TRUE(same_bits(Q::kYInvStd[i], static_cast<float>(1.0 / m.norm.y.std(i))));
    EXPECT_TRUE(same_bits(F::kYInvStd[i], Q::kYInvStd[i]));
  }
  for (int i = 0; i < Q::kU; ++i) {
    EXPECT_EQ(std::string(Q::kUNames[i]), m.layout.u_names[static_cast<std::size_t>(i)]);
    EXPECT_TRUE(same_bits(Q::kUMean[i], static_cast<float>(m.norm.u.mean(i))));
    EXPECT_TRUE(same_bits(Q::kUStd[i], static_cast<float>(m.norm.u.std(i))));
    EXPECT_TRUE(same_bits(Q::kUInvStd[i], static_cast<float>(1.0 / m.norm.u.std(i))));
  }
  for (int i = 0; i < Q::kX; ++i) {
    const auto k = static_cast<std::size_t>(i);
    EXPECT_EQ(Q::kXSource[i], m.layout.x_source[k]);
    EXPECT_EQ(Q::kXIsDelta[i], m.layout.x_is_delta[k]);
    // The x channel is its y channel or that channel's "d" difference.
    const std::string y_name = m.layout.y_names[static_cast<std::size_t>(Q::kXSource[i])];
    EXPECT_EQ(m.layout.x_names[k], (Q::kXIsDelta[i] ? "d" : "") + y_name);
    EXPECT_TRUE(same_bits(Q::kXMean[i], static_cast<float>(m.norm.x.mean(i))));
    EXPECT_TRUE(same_bits(Q::kXInvStd[i], static_cast<float>(1.0 / m.norm.x.std(i))));
  }
}

TEST(DefaultModel, Q15WeightsAreRealToFixedOfTheFoldedFloatWeights) {
  const HadynetModel& m = model();
  const auto& p = m.params;
  const hadynet::trainer::FoldedEncoder enc = hadynet::trainer::fold_batch_norm(p);
  // Exact: every raw value is real_to_fixed of the float weight (0 mismatches);
  // dequantised within 0.5 LSB (round to nearest, no saturation).
  const QuantCheck ew = check_q<std::int16_t, Q::kFracEncW>(
      Q::kEncWeight, [&](Eigen::Index i, Eigen::Index j) { return enc.weight(i, j); });
  const QuantCheck ih = check_q<std::int16_t, Q::kFracLstmW>(
      Q::kLstmWeightIh, [&](Eigen::Index i, Eigen::Index j) { return p.lstm_weight_ih(i, j); });
  const QuantCheck hh = check_q<std::int16_t, Q::kFracLstmW>(
      Q::kLstmWeightHh, [&](Eigen::Index i, Eigen::Index j) { return p.lstm_weight_hh(i, j); });
  const QuantCheck dw = check_q<std::int16_t, Q::kFracDecW>(
      Q::kDecWeight, [&](Eigen::Index i, Eigen::Index j) { return p.dec_weight(i, j); });
  for (const QuantCheck& c : {ew, ih, hh, dw}) {
    EXPECT_EQ(c.mismatches, 0);
    EXPECT_LE(c.max_error_lsb, 0.5);
  }
  // Formats from the exact maxima: the largest raw value uses the top bit
  // (>= 2^14) unless the format is already Q15.
  EXPECT_TRUE(Q::kFracEncW == 15 || ew.max_raw >= 16384) << ew.max_raw;
  EXPECT_TRUE(Q::kFracLstmW == 15 || std::max(ih.max_raw, hh.max_raw) >= 16384);
  EXPECT_TRUE(Q::kFracDecW == 15 || dw.max_raw >= 16384) << dw.max_raw;

  // Biases: int32 in the accumulator formats, exactly real_to_fixed.
  const QuantCheck eb = check_q<std::int32_t, Q::kFracEncW + Q::kFracIn>(
      Q::kEncBias, [&](Eigen::Index i) { return static_cast<double>(enc.bias(i)); });
  const QuantCheck lb = check_q<std::int32_t, Q::kFracLstmAcc>(Q::kLstmBias, [&](Eigen::Index i) {
    return static_cast<double>(p.lstm_bias_ih(i)) + static_cast<double>(p.lstm_bias_hh(i));
  });
  const QuantCheck db = check_q<std::int32_t, Q::kFracDecW + Q::kFracH>(
      Q::kDecBias, [&](Eigen::Index i) { return static_cast<double>(p.dec_bias(i)); });
  for (const QuantCheck& c : {eb, lb, db}) {
    EXPECT_EQ(c.mismatches, 0);
    EXPECT_LE(c.max_error_lsb, 0.5);
  }
}

TEST(DefaultModel, F32WeightsAreTheFloatWeightsExactly) {
  const HadynetModel& m = model();
  const auto& p = m.params;
  const hadynet::trainer::FoldedEncoder enc = hadynet::trainer::fold_batch_norm(p);
  EXPECT_EQ(f32_mismatches(F::kEncWeight, [&](Eigen::Index i, Eigen::Index j) { return enc.weight(i, j); }), 0);
  EXPECT_EQ(f32_mismatches(F::kEncBias, [&](Eigen::Index i) { return enc.bias(i); }), 0);
  EXPECT_EQ(f32_mismatches(F::kLstmWeightIh,
                           [&](Eigen::Index i, Eigen::Index j) { return p.lstm_weight_ih(i, j); }),
            0);
  EXPECT_EQ(f32_mismatches(F::kLstmWeightHh,
                           [&](Eigen::Index i, Eigen::Index j) { return p.lstm_weight_hh(i, j); }),
            0);
  // b_ih + b_hh summed in double, rounded once to float.
  EXPECT_EQ(f32_mismatches(F::kLstmBias,
                           [&](Eigen::Index i) {
                             return static_cast<float>(static_cast<double>(p.lstm_bias_ih(i)) +
                                                       static_cast<double>(p.lstm_bias_hh(i)));
                           }),
            0);
  EXPECT_EQ(f32_mismatches(F::kDecWeight, [&](Eigen::Index i, Eigen::Index j) { return p.dec_weight(i, j); }), 0);
  EXPECT_EQ(f32_mismatches(F::kDecBias, [&](Eigen::Index i) { return p.dec_bias(i); }), 0);
  EXPECT_EQ(f32_mismatches(F::kPbTable, [&](Eigen::Index i, Eigen::Index j) { return p.pb(i, j); }), 0);
}

TEST(DefaultModel, PbTableAndStates) {
  const HadynetModel& m = model();
  const QuantCheck pb = check_q<std::int16_t, Q::kFracIn>(
      Q::kPbTable, [&](Eigen::Index i, Eigen::Index j) { return m.params.pb(i, j); });
  EXPECT_EQ(pb.mismatches, 0);
  EXPECT_LE(pb.max_error_lsb, 0.5);
  ASSERT_EQ(static_cast<std::size_t>(Q::kStates), m.states.size());
  for (std::size_t k = 0; k < m.states.size(); ++k) {
    EXPECT_EQ(std::string(Q::kStateNames[k]), m.states[k].name);
    EXPECT_EQ(std::string(Q::kStateObjects[k]), m.states[k].object);
    EXPECT_EQ(std::string(F::kStateNames[k]), m.states[k].name);
  }
}

TEST(DefaultModel, DetectionStatistics) {
  const HadynetModel& m = model();
  ASSERT_TRUE(m.detection.has_value()) << "the default model is calibrated for detection";
  const auto& c = *m.detection;
  EXPECT_TRUE(Q::kHasDetection);
  EXPECT_EQ(Q::kDetectSteps, c.steps);
  EXPECT_EQ(F::kDetectSteps, c.steps);
  const QuantCheck pb = check_q<std::int16_t, Q::kFracIn>(Q::kDetectPb, [&](Eigen::Index i) { return c.pb(i); });
  const QuantCheck mean =
      check_q<std::int16_t, Q::kFracY>(Q::kDetectMean, [&](Eigen::Index i) { return c.mean(i); });
  EXPECT_EQ(pb.mismatches, 0);
  EXPECT_EQ(mean.mismatches, 0);
  EXPECT_EQ(f32_mismatches(F::kDetectPb, [&](Eigen::Index i) { return static_cast<float>(c.pb(i)); }), 0);
  EXPECT_EQ(f32_mismatches(F::kDetectMean, [&](Eigen::Index i) { return static_cast<float>(c.mean(i)); }), 0);
  EXPECT_TRUE(same_bits(Q::kDetectThreshold, static_cast<float>(c.threshold)));
  EXPECT_EQ(Q::kDetectThresholdSq,
            (fixed::real_to_fixed<std::int64_t, 2 * Q::kFracZ>(c.threshold * c.threshold)));
  EXPECT_TRUE(same_bits(F::kDetectThresholdSq, static_cast<float>(c.threshold * c.threshold)));

  // W^T W = Sigma_e^-1 (S). f32: W rounded to float, |dW| <= u |W| with
  // u = 2^-24, so |d(W^T W)_ij| <= (2u + u^2) sum_k |W_ki||W_kj|
  // <= (2u + u^2) sqrt(S_ii S_jj) (Cauchy-Schwarz); bound 4u sqrt(S_ii S_jj)
  // plus 1e-12 max|S| for the double eigendecomposition.
  const Eigen::MatrixXd& s = c.inverse;
  const int n = Q::kY;
  Eigen::MatrixXd wf(n, n), wq(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      wf(i, j) = F::kDetectWhiten[i][j];
      wq(i, j) = fixed::to_real<Q::kFracWhiten, double>(Q::kDetectWhiten[i][j]);
    }
  }
  const double u = std::ldexp(1.0, -24);
  const double eig = 1e-12 * s.cwiseAbs().maxCoeff();
  const Eigen::MatrixXd sf = wf.transpose() * wf;
  // q15: |dW| <= delta = half an LSB, so |d(W^T W)_ij| <= delta sum_k (|W_ki| + |W_kj|)
  // + n delta^2 <= delta sum_k (|Wq_ki| + |Wq_kj|) + 3 n delta^2.
  const double delta = half_lsb(Q::kFracWhiten);
  const Eigen::MatrixXd sq = wq.transpose() * wq;
  const Eigen::VectorXd col_abs = wq.cwiseAbs().colwise().sum().transpose();
  long f_bad = 0, q_bad = 0;
  double q_worst = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (std::abs(sf(i, j) - s(i, j)) > 4 * u * std::sqrt(s(i, i) * s(j, j)) + eig) ++f_bad;
      const double bound = delta * (col_abs(i) + col_abs(j)) + 3 * n * delta * delta + eig;
      if (std::abs(sq(i, j) - s(i, j)) > bound) ++q_bad;
      q_worst = std::max(q_worst, std::abs(sq(i, j) - s(i, j)) / bound);
    }
  }
  EXPECT_EQ(f_bad, 0);
  EXPECT_EQ(q_bad, 0) << "worst error / bound " << q_worst;
  // kFracWhiten from max |W|: the largest raw value uses the top bit.
  EXPECT_TRUE(Q::kFracWhiten == 15 || wq.cwiseAbs().maxCoeff() >= std::ldexp(16384.0, -Q::kFracWhiten));
}

TEST(DefaultModel, ControlConstants) {
  const HadynetModel& m = model();
  EXPECT_EQ(Q::kControlHorizon, 8);
  EXPECT_EQ(Q::kControlEpochs, 3);
  EXPECT_EQ(Q::kControlAlphaCount, 4);
  EXPECT_EQ(Q::kControlTruncation, 8);  // = horizon: full BPTT
  const double alphas[] = {1.0, 0.5, 0.25, 0.125};
  for (int k = 0; k < 4; ++k) {
    // Powers of two: exact in any Q format that holds them.
    EXPECT_EQ((fixed::to_real<Q::kFracIn, double>(Q::kControlAlpha[k])), alphas[k]);
    EXPECT_EQ(F::kControlAlpha[k], static_cast<float>(alphas[k]));
  }
  // Loss classes by channel group; weights (beta 3, w2 = w3 = 1) in
  // physical units: class weight x std^2, the largest scaled to 1 (Q14).
  double largest = 0;
  for (int i = 0; i < Q::kY; ++i) {
    const std::string group = hadynet::trainer::channel_group(m.layout.y_names[static_cast<std::size_t>(i)]);
    const double s2 = m.norm.y.std(i) * m.norm.y.std(i);
    largest = std::max(largest, (group == "f" || group == "fc" ? 3.0 : 1.0) * s2);
  }
  for (int i = 0; i < Q::kY; ++i) {
    const std::string group = hadynet::trainer::channel_group(m.layout.y_names[static_cast<std::size_t>(i)]);
    LossClass want = LossClass::kNone;
    double up = 0, down = 0;
    if (group == "f" || group == "fc") {
      want = LossClass::kForce;
      up = 1;
      down = 3;
    } else if (group == "th" || group == "l") {
      want = group == "th" ? LossClass::kAngle : LossClass::kLength;
      up = down = 1;
    }
    const double s2 = m.norm.y.std(i) * m.norm.y.std(i) / largest;
    EXPECT_EQ(Q::kLossClass[i], want) << group;
    EXPECT_EQ(F::kLossClass[i], want) << group;
    EXPECT_EQ(Q::kLossWeightUp[i], std::lround(up * s2 * 16384)) << group;
    EXPECT_EQ(Q::kLossWeightDown[i], std::lround(down * s2 * 16384)) << group;
    EXPECT_NEAR(F::kLossWeightUp[i], up * s2, 1e-6) << group;
    EXPECT_NEAR(F::kLossWeightDown[i], down * s2, 1e-6) << group;
  }
}

TEST(DefaultModel, FormatsFollowTheRuleFromTheStoredRanges) {
  const HadynetModel& m = model();
  ASSERT_TRUE(m.ranges.has_value());
  const auto& r = *m.ranges;
  const double headroom = 1.5;  // the build runs codegen with the default
  const double pb_table = m.params.pb.cwiseAbs().maxCoeff();
  const double detect_pb = m.detection ? m.detection->pb.cwiseAbs().maxCoeff() : 0.0;
  const double detect_mean = m.detection ? m.detection->mean.cwiseAbs().maxCoeff() : 0.0;
  EXPECT_TRUE(is_rule_format(std::max({headroom * r.x, headroom * r.u, pb_table, detect_pb, 1.0}),
                             Q::kFracIn));
  EXPECT_TRUE(is_rule_format(headroom * r.h, Q::kFracH));
  EXPECT_TRUE(is_rule_format(headroom * r.c, Q::kFracC));
  EXPECT_TRUE(is_rule_format(std::max(headroom * r.y, detect_mean), Q::kFracY));
  EXPECT_TRUE(is_rule_format(r.enc_weight, Q::kFracEncW));
  EXPECT_TRUE(is_rule_format(r.lstm_weight, Q::kFracLstmW));
  EXPECT_TRUE(is_rule_format(r.dec_weight, Q::kFracDecW));
  if (m.detection) {
    EXPECT_TRUE(is_rule_format(4 * m.detection->threshold, Q::kFracZ));
  }
  EXPECT_EQ(Q::kFracLstmAcc, Q::kFracLstmW + std::max(Q::kFracIn, Q::kFracH));
  EXPECT_EQ(Q::kFracGate, 12);
  EXPECT_EQ(Q::kFracLossW, 14);  // physical units: the largest weight is 1.0
  for (const int f : {F::kFracIn, F::kFracH, F::kFracC, F::kFracY, F::kFracGate, F::kFracEncW,
                      F::kFracLstmW, F::kFracLstmAcc, F::kFracDecW, F::kFracWhiten, F::kFracZ,
                      F::kFracLossW}) {
    EXPECT_EQ(f, 0);
  }
}

TEST(DefaultModel, TheBuildsHeadersAreWhatTheGeneratorWritesNow) {
  // Determinism across processes: the build's files equal a fresh generate().
  const hadynet::codegen::LoadedModel loaded = hadynet::codegen::load_model_file(HADYNET_MODEL_PATH);
  for (const auto numeric : {hadynet::codegen::Numeric::kQ15, hadynet::codegen::Numeric::kF32}) {
    hadynet::codegen::CodegenOptions o;
    o.numeric = numeric;
    // The build's HADYNET_CODEGEN_OPTIONS (space-separated here): only
    // --control-commands is understood.
    const std::string build_options = HADYNET_CODEGEN_OPTIONS;
    if (!build_options.empty()) {
      const std::string flag = "--control-commands ";
      if (build_options.rfind(flag, 0) != 0 || build_options.find(' ', flag.size()) != std::string::npos)
        GTEST_SKIP() << "HADYNET_CODEGEN_OPTIONS '" << build_options << "' is more than --control-commands";
      std::string list = build_options.substr(flag.size());
      o.control.commands.emplace();
      for (std::size_t pos = 0; pos <= list.size();) {
        const std::size_t comma = std::min(list.find(',', pos), list.size());
        o.control.commands->push_back(list.substr(pos, comma - pos));
        pos = comma + 1;
      }
    }
    const hadynet::codegen::GeneratedHeader h = hadynet::codegen::generate(loaded.model, loaded.identity, o);
    EXPECT_EQ(file_bytes(std::string(HADYNET_GENERATED_MODEL_DIR) + "/" + h.file_name), h.text)
        << h.file_name;
  }
}

}  // namespace
