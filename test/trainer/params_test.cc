// HadynetParams: names, shapes and order of the tensors, initialisation,
// conversion between float and double, shape validation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "test_batches.h"
#include "trainer/hadynet_params.h"

namespace hadynet::trainer {
namespace {

using testing::bit_identical;

const HadynetDims kDims{37, 8, 27, 8, 128, 6};

TEST(HadynetDims, DefaultsAndValidation) {
  const HadynetDims d;
  EXPECT_EQ(d.hidden, 128);
  EXPECT_EQ(d.pb, 8);
  EXPECT_THROW(validate(d), std::invalid_argument);  // x, u, y, states unset
  EXPECT_NO_THROW(validate(kDims));
  HadynetDims bad = kDims;
  bad.hidden = 0;
  EXPECT_THROW(validate(bad), std::invalid_argument);
}

TEST(HadynetParams, TensorsHavePyTorchNamesShapesAndOrder) {
  HadynetParams<float> p = HadynetParams<float>::zeros(kDims);
  struct Want {
    const char* name;
    int rank, rows, cols;
    bool trainable;
  };
  const std::vector<Want> want{
      {"enc.weight", 2, 128, 45, true},
      {"enc.bias", 1, 128, 1, true},
      {"enc_bn.weight", 1, 128, 1, true},
      {"enc_bn.bias", 1, 128, 1, true},
      {"enc_bn.running_mean", 1, 128, 1, false},
      {"enc_bn.running_var", 1, 128, 1, false},
      {"lstm.weight_ih_l0", 2, 512, 16, true},
      {"lstm.weight_hh_l0", 2, 512, 128, true},
      {"lstm.bias_ih_l0", 1, 512, 1, true},
      {"lstm.bias_hh_l0", 1, 512, 1, true},
      {"dec.weight", 2, 27, 128, true},
      {"dec.bias", 1, 27, 1, true},
      {"pb", 2, 6, 8, true},
  };
  const std::vector<NamedTensor<float>> t = p.tensors();
  ASSERT_EQ(t.size(), want.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_EQ(t[i].name, want[i].name);
    EXPECT_EQ(t[i].rank, want[i].rank) << want[i].name;
    EXPECT_EQ(t[i].rows, want[i].rows) << want[i].name;
    EXPECT_EQ(t[i].cols, want[i].cols) << want[i].name;
    EXPECT_EQ(t[i].trainable, want[i].trainable) << want[i].name;
  }
  EXPECT_NO_THROW(p.check_shapes());
}

TEST(HadynetParams, DataIsRowMajorOutByIn) {
  HadynetParams<double> p = HadynetParams<double>::zeros(kDims);
  p.lstm_weight_ih(2, 5) = 7.0;  // row 2 (gate i, unit 2), input column 5
  const NamedTensor<double> t = p.tensors()[6];
  EXPECT_EQ(t.data[2 * t.cols + 5], 7.0);
}

TEST(HadynetParams, InitialisationFollowsPyTorch) {
  const HadynetParams<double> p = HadynetParams<double>::initialized(kDims, 42);
  const double enc_bound = 1.0 / std::sqrt(45.0);
  const double lstm_bound = 1.0 / std::sqrt(128.0);
  EXPECT_LE(p.enc_weight.cwiseAbs().maxCoeff(), enc_bound);
  EXPECT_GT(p.enc_weight.cwiseAbs().maxCoeff(), 0.95 * enc_bound);
  EXPECT_LE(p.enc_bias.cwiseAbs().maxCoeff(), enc_bound);
  EXPECT_LE(p.lstm_weight_ih.cwiseAbs().maxCoeff(), lstm_bound);
  EXPECT_GT(p.lstm_weight_ih.cwiseAbs().maxCoeff(), 0.95 * lstm_bound);
  EXPECT_LE(p.lstm_weight_hh.cwiseAbs().maxCoeff(), lstm_bound);
  EXPECT_LE(p.lstm_bias_hh.cwiseAbs().maxCoeff(), lstm_bound);
  EXPECT_LE(p.dec_weight.cwiseAbs().maxCoeff(), lstm_bound);
  EXPECT_NEAR(p.lstm_weight_hh.mean(), 0.0,
              0.1 * lstm_bound);  // 65536 draws: std of the mean ~ 0.003 bound
  EXPECT_TRUE((p.enc_bn_weight.array() == 1.0).all());
  EXPECT_TRUE((p.enc_bn_bias.array() == 0.0).all());
  EXPECT_TRUE((p.enc_bn_running_mean.array() == 0.0).all());
  EXPECT_TRUE((p.enc_bn_running_var.array() == 1.0).all());
  EXPECT_TRUE((p.pb.array() == 0.0).all());
}

TEST(HadynetParams, SameSeedSameValuesOtherSeedOtherValues) {
  const auto a = HadynetParams<float>::initialized(kDims, 5);
  EXPECT_TRUE(bit_identical(a, HadynetParams<float>::initialized(kDims, 5)));
  EXPECT_FALSE(bit_identical(a, HadynetParams<float>::initialized(kDims, 6)));
}

TEST(HadynetParams, FloatInitIsRoundedDoubleInit) {
  const auto d = HadynetParams<double>::initialized(kDims, 9);
  EXPECT_TRUE(bit_identical(HadynetParams<float>::initialized(kDims, 9), d.cast<float>()));
  // float -> double -> float is exact
  const auto f = d.cast<float>();
  EXPECT_TRUE(bit_identical(f, f.cast<double>().cast<float>()));
  EXPECT_EQ(f.cast<double>().dims, kDims);
}

TEST(HadynetParams, CheckShapesNamesTheTensor) {
  HadynetParams<float> p = HadynetParams<float>::zeros(kDims);
  p.dec_bias.resize(26);
  try {
    p.check_shapes();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("dec.bias"), std::string::npos) << e.what();
  }
}

TEST(GroupSet, SetOperations) {
  EXPECT_TRUE(GroupSet::all().contains(ParamGroup::kPb));
  EXPECT_FALSE(GroupSet::weights().contains(ParamGroup::kPb));
  EXPECT_TRUE(GroupSet::weights().contains(ParamGroup::kLstm));
  EXPECT_EQ(GroupSet::only(ParamGroup::kPb), GroupSet().with(ParamGroup::kPb));
  EXPECT_FALSE(GroupSet::only(ParamGroup::kPb).contains(ParamGroup::kEncoder));
}

}  // namespace
}  // namespace hadynet::trainer
