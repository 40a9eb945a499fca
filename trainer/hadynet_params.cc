#include "trainer/hadynet_params.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace hadynet::trainer {

void validate(const HadynetDims& dims) {
  const auto require = [](int value, const char* field) {
    if (value < 1) {
      throw std::invalid_argument(std::string("HadynetDims.") + field + " must be >= 1, got " +
                                  std::to_string(value));
    }
  };
  require(dims.x, "x");
  require(dims.u, "u");
  require(dims.y, "y");
  require(dims.pb, "pb");
  require(dims.hidden, "hidden");
  require(dims.states, "states");
}

namespace {

// Views of all tensors of `p` (HadynetParams<S> or const HadynetParams<S>).
template <class Elem, class Params>
std::vector<NamedTensor<Elem>> views_of(Params& p) {
  const auto mat = [](std::string_view name, ParamGroup group, auto& m) {
    return NamedTensor<Elem>{
        name, group, true, 2, static_cast<int>(m.rows()), static_cast<int>(m.cols()), m.data()};
  };
  const auto vec = [](std::string_view name, ParamGroup group, auto& v, bool trainable = true) {
    return NamedTensor<Elem>{name, group, trainable, 1, static_cast<int>(v.size()), 1, v.data()};
  };
  return {
      mat("enc.weight", ParamGroup::kEncoder, p.enc_weight),
      vec("enc.bias", ParamGroup::kEncoder, p.enc_bias),
      vec("enc_bn.weight", ParamGroup::kEncoderBn, p.enc_bn_weight),
      vec("enc_bn.bias", ParamGroup::kEncoderBn, p.enc_bn_bias),
      vec("enc_bn.running_mean", ParamGroup::kEncoderBn, p.enc_bn_running_mean, false),
      vec("enc_bn.running_var", ParamGroup::kEncoderBn, p.enc_bn_running_var, false),
      mat("lstm.weight_ih_l0", ParamGroup::kLstm, p.lstm_weight_ih),
      mat("lstm.weight_hh_l0", ParamGroup::kLstm, p.lstm_weight_hh),
      vec("lstm.bias_ih_l0", ParamGroup::kLstm, p.lstm_bias_ih),
      vec("lstm.bias_hh_l0", ParamGroup::kLstm, p.lstm_bias_hh),
      mat("dec.weight", ParamGroup::kDecoder, p.dec_weight),
      vec("dec.bias", ParamGroup::kDecoder, p.dec_bias),
      mat("pb", ParamGroup::kPb, p.pb),
  };
}

// Uniform in [-bound, +bound): top 53 bits of the generator as a double in
// [0, 1), mapped affinely. Independent of the standard library's distributions,
// so the sequence is the same with every compiler.
double uniform_symmetric(std::mt19937_64& rng, double bound) {
  const double unit = static_cast<double>(rng() >> 11) * 0x1.0p-53;
  return bound * (2.0 * unit - 1.0);
}

constexpr std::size_t kTensorCount = 13;
struct Shape {
  int rows;
  int cols;
};

// Shapes in tensors() order.
std::array<Shape, kTensorCount> expected_shapes(const HadynetDims& d) {
  const int h = d.hidden;
  return {{{h, d.x + d.pb},
           {h, 1},
           {h, 1},
           {h, 1},
           {h, 1},
           {h, 1},
           {4 * h, d.u + d.pb},
           {4 * h, h},
           {4 * h, 1},
           {4 * h, 1},
           {d.y, h},
           {d.y, 1},
           {d.states, d.pb}}};
}

}  // namespace

template <class S>
HadynetParams<S> HadynetParams<S>::zeros(const HadynetDims& dims) {
  validate(dims);
  const int h = dims.hidden;
  HadynetParams p;
  p.dims = dims;
  p.enc_weight = RowMatrix<S>::Zero(h, dims.x + dims.pb);
  p.enc_bias = Vector<S>::Zero(h);
  p.enc_bn_weight = Vector<S>::Zero(h);
  p.enc_bn_bias = Vector<S>::Zero(h);
  p.enc_bn_running_mean = Vector<S>::Zero(h);
  p.enc_bn_running_var = Vector<S>::Zero(h);
  p.lstm_weight_ih = RowMatrix<S>::Zero(4 * h, dims.u + dims.pb);
  p.lstm_weight_hh = RowMatrix<S>::Zero(4 * h, h);
  p.lstm_bias_ih = Vector<S>::Zero(4 * h);
  p.lstm_bias_hh = Vector<S>::Zero(4 * h);
  p.dec_weight = RowMatrix<S>::Zero(dims.y, h);
  p.dec_bias = Vector<S>::Zero(dims.y);
  p.pb = RowMatrix<S>::Zero(dims.states, dims.pb);
  return p;
}

template <class S>
HadynetParams<S> HadynetParams<S>::initialized(const HadynetDims& dims, std::uint64_t seed) {
  HadynetParams p = zeros(dims);
  std::mt19937_64 rng(seed);
  const double enc_bound = 1.0 / std::sqrt(static_cast<double>(dims.x + dims.pb));
  const double lstm_bound = 1.0 / std::sqrt(static_cast<double>(dims.hidden));
  const double dec_bound = 1.0 / std::sqrt(static_cast<double>(dims.hidden));
  for (NamedTensor<S>& t : p.tensors()) {
    double bound = 0.0;
    switch (t.group) {
      case ParamGroup::kEncoder:
        bound = enc_bound;
        break;
      case ParamGroup::kLstm:
        bound = lstm_bound;
        break;
      case ParamGroup::kDecoder:
        bound = dec_bound;
        break;
      case ParamGroup::kEncoderBn:
      case ParamGroup::kPb:
        continue;
    }
    for (int i = 0; i < t.size(); ++i) t.data[i] = static_cast<S>(uniform_symmetric(rng, bound));
  }
  p.enc_bn_weight.setOnes();
  p.enc_bn_running_var.setOnes();
  return p;
}

template <class S>
std::vector<NamedTensor<S>> HadynetParams<S>::tensors() {
  return views_of<S>(*this);
}

template <class S>
std::vector<NamedTensor<const S>> HadynetParams<S>::tensors() const {
  return views_of<const S>(*this);
}

template <class S>
void HadynetParams<S>::set_zero() {
  for (NamedTensor<S>& t : tensors()) std::fill(t.data, t.data + t.size(), S(0));
}

template <class S>
void HadynetParams<S>::check_shapes() const {
  validate(dims);
  const std::array<Shape, kTensorCount> want = expected_shapes(dims);
  const std::vector<NamedTensor<const S>> have = tensors();
  for (std::size_t i = 0; i < want.size(); ++i) {
    if (have[i].rows != want[i].rows || have[i].cols != want[i].cols) {
      throw std::invalid_argument(
          "tensor " + std::string(have[i].name) + " is " + std::to_string(have[i].rows) + "x" +
          std::to_string(have[i].cols) + ", dims say " + std::to_string(want[i].rows) + "x" +
          std::to_string(want[i].cols));
    }
  }
}

template struct HadynetParams<float>;
template struct HadynetParams<double>;

}  // namespace hadynet::trainer
