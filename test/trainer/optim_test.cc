// Adam and MomentumSgd against their formulas written out per element in
// double, and freezing of groups.
#include "trainer/optim.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "test_batches.h"

namespace hadynet::trainer::testing {
namespace {

const HadynetDims kDims{3, 2, 3, 2, 4, 3};

HadynetParams<double> random_grads(std::uint64_t seed) {
  HadynetParams<double> g = HadynetParams<double>::zeros(kDims);
  std::mt19937_64 rng(seed);
  for (NamedTensor<double>& t : g.tensors()) {
    for (int i = 0; i < t.size(); ++i) t.data[i] = uniform(rng, -1.0, 1.0);
  }
  return g;
}

bool tensor_equal(const NamedTensor<const double>& a, const NamedTensor<const double>& b) {
  return std::memcmp(a.data, b.data, sizeof(double) * a.size()) == 0;
}

TEST(Adam, ThreeStepsFollowTheFormula) {
  const HadynetParams<double> start = generic_params(kDims, 1);
  const std::vector<HadynetParams<double>> grads{random_grads(2), random_grads(3), random_grads(4)};
  Adam<double>::Options o;
  o.lr = 0.01;
  Adam<double> adam(o);
  HadynetParams<double> p = start;
  for (const auto& g : grads) adam.step(p, g);

  const auto got = std::as_const(p).tensors();
  const auto before = start.tensors();
  for (std::size_t t = 0; t < got.size(); ++t) {
    if (!got[t].trainable) {
      EXPECT_TRUE(tensor_equal(got[t], before[t])) << got[t].name;
      continue;
    }
    for (int i = 0; i < got[t].size(); ++i) {
      double value = before[t].data[i], m = 0.0, v = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double g = grads[k].tensors()[t].data[i];
        m = 0.9 * m + 0.1 * g;
        v = 0.999 * v + 0.001 * g * g;
        const double m_hat = m / (1.0 - std::pow(0.9, k + 1));
        const double v_hat = v / (1.0 - std::pow(0.999, k + 1));
        value -= 0.01 * m_hat / (std::sqrt(v_hat) + 1e-8);
      }
      EXPECT_NEAR(got[t].data[i], value, 1e-14) << got[t].name << "[" << i << "]";
    }
  }
}

TEST(Adam, DefaultsArePyTorchs) {
  const Adam<float> adam({});
  EXPECT_EQ(adam.options().lr, 1e-3);
  EXPECT_EQ(adam.options().beta1, 0.9);
  EXPECT_EQ(adam.options().beta2, 0.999);
  EXPECT_EQ(adam.options().eps, 1e-8);
  EXPECT_EQ(adam.trainable(), GroupSet::all());
}

TEST(Adam, FrozenGroupsDoNotMove) {
  const HadynetParams<double> start = generic_params(kDims, 5);
  HadynetParams<double> p = start;
  Adam<double> adam({}, GroupSet::only(ParamGroup::kPb).with(ParamGroup::kDecoder));
  adam.step(p, random_grads(6));
  const auto got = std::as_const(p).tensors();
  const auto before = start.tensors();
  for (std::size_t t = 0; t < got.size(); ++t) {
    const bool moves = got[t].group == ParamGroup::kPb || got[t].group == ParamGroup::kDecoder;
    EXPECT_EQ(!tensor_equal(got[t], before[t]), moves) << got[t].name;
  }
}

TEST(Adam, WrongGradientShapeIsRejected) {
  HadynetParams<double> p = generic_params(kDims, 7);
  HadynetDims other = kDims;
  other.hidden = 5;
  Adam<double> adam({});
  EXPECT_THROW(adam.step(p, HadynetParams<double>::zeros(other)), std::invalid_argument);
}

TEST(MomentumSgd, TwoStepsFollowTheFormulaAndOnlyPbMoves) {
  const HadynetParams<double> start = generic_params(kDims, 8);
  const HadynetParams<double> g1 = random_grads(9);
  const HadynetParams<double> g2 = random_grads(10);
  MomentumSgd<double> sgd({0.05, 0.9});
  EXPECT_EQ(sgd.trainable(), GroupSet::only(ParamGroup::kPb));
  HadynetParams<double> p = start;
  sgd.step(p, g1);
  sgd.step(p, g2);
  for (Eigen::Index i = 0; i < p.pb.size(); ++i) {
    // buf1 = g1; buf2 = 0.9 g1 + g2; p = p0 - lr buf1 - lr buf2
    const double expected = start.pb.data()[i] - 0.05 * g1.pb.data()[i] -
                            0.05 * (0.9 * g1.pb.data()[i] + g2.pb.data()[i]);
    EXPECT_NEAR(p.pb.data()[i], expected, 1e-15);
  }
  const auto got = std::as_const(p).tensors();
  const auto before = start.tensors();
  for (std::size_t t = 0; t + 1 < got.size(); ++t) {  // all but pb
    EXPECT_TRUE(tensor_equal(got[t], before[t])) << got[t].name;
  }
}

TEST(MomentumSgd, DefaultsMatchChainer) {
  const MomentumSgd<float> sgd({});
  EXPECT_EQ(sgd.options().lr, 0.01);
  EXPECT_EQ(sgd.options().momentum, 0.9);
}

}  // namespace
}  // namespace hadynet::trainer::testing
