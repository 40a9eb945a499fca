// HADYNET parameters (docs/method.md, "Network"): every tensor of the model with
// PyTorch names and layouts, a uniform view of them for optimisers and model
// I/O, and PyTorch-style initialisation from a seed.
//
// Layout contract: a weight is `out x in`, stored row-major, so data() is the
// same byte order as the PyTorch tensor (and as a safetensors payload).
// Vectors (biases, BN tensors) are rank-1 tensors of shape [n].
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string_view>
#include <vector>

namespace hadynet::trainer {

// The encoder batch norm's epsilon (PyTorch BatchNorm1d's default), in the
// network (hadynet_network.h) and in the fold (batch_norm_fold.h).
inline constexpr double kBnEps = 1e-5;

// Sizes of one model. All come from the data (column counts of the logs);
// nothing in the trainer assumes the paper's 37/8/27.
struct HadynetDims {
  int x = 0;         // initial-state features per window (paper: 37)
  int u = 0;         // command features per step (paper: 8)
  int y = 0;         // observed features per step (paper: 27)
  int pb = 8;        // parametric bias size
  int hidden = 128;  // LSTM units
  int states = 0;    // rows of the PB table (one per dynamics state)

  bool operator==(const HadynetDims&) const = default;
};

// Throws std::invalid_argument naming the first field that is < 1.
void validate(const HadynetDims& dims);

template <class S>
using RowMatrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
template <class S>
using Matrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;  // column-major
template <class S>
using Vector = Eigen::Matrix<S, Eigen::Dynamic, 1>;

// Parameter groups, the unit of freezing in the optimisers.
enum class ParamGroup : unsigned {
  kEncoder = 0,    // enc.weight, enc.bias
  kEncoderBn = 1,  // enc_bn.weight, enc_bn.bias (+ running stats, never trained)
  kLstm = 2,       // lstm.*
  kDecoder = 3,    // dec.*
  kPb = 4,         // pb table
};

// A set of ParamGroup values.
class GroupSet {
 public:
  constexpr GroupSet() = default;
  static constexpr GroupSet all() { return GroupSet(0x1fu); }
  static constexpr GroupSet weights() { return all().without(ParamGroup::kPb); }
  static constexpr GroupSet only(ParamGroup g) { return GroupSet().with(g); }
  constexpr GroupSet with(ParamGroup g) const { return GroupSet(bits_ | bit(g)); }
  constexpr GroupSet without(ParamGroup g) const { return GroupSet(bits_ & ~bit(g)); }
  constexpr bool contains(ParamGroup g) const { return (bits_ & bit(g)) != 0; }
  constexpr bool operator==(const GroupSet&) const = default;

 private:
  constexpr explicit GroupSet(unsigned bits) : bits_(bits) {}
  static constexpr unsigned bit(ParamGroup g) { return 1u << static_cast<unsigned>(g); }
  unsigned bits_ = 0;
};

// One named tensor. S is `float`, `double` or a const of them.
template <class S>
struct NamedTensor {
  std::string_view name;  // PyTorch state_dict key, e.g. "lstm.weight_ih_l0"
  ParamGroup group;
  bool trainable;  // false for BN running statistics (PyTorch buffers)
  int rank;        // 1: shape [rows] (cols == 1); 2: shape [rows, cols]
  int rows;
  int cols;
  S* data;  // rows * cols values, row-major

  int size() const { return rows * cols; }
};

template <class S>
struct HadynetParams {
  HadynetDims dims;
  RowMatrix<S> enc_weight;        // enc.weight            hidden x (x + pb), input [x ; p]
  Vector<S> enc_bias;             // enc.bias              hidden
  Vector<S> enc_bn_weight;        // enc_bn.weight (gamma) hidden
  Vector<S> enc_bn_bias;          // enc_bn.bias (beta)    hidden
  Vector<S> enc_bn_running_mean;  // enc_bn.running_mean   hidden (buffer)
  Vector<S> enc_bn_running_var;   // enc_bn.running_var    hidden (buffer, unbiased)
  RowMatrix<S> lstm_weight_ih;    // lstm.weight_ih_l0     4*hidden x (u + pb), input [u ; p];
                                  //   row blocks of `hidden`: gates i, f, g, o
  RowMatrix<S> lstm_weight_hh;    // lstm.weight_hh_l0     4*hidden x hidden
  Vector<S> lstm_bias_ih;         // lstm.bias_ih_l0       4*hidden
  Vector<S> lstm_bias_hh;         // lstm.bias_hh_l0       4*hidden
  RowMatrix<S> dec_weight;        // dec.weight            y x hidden
  Vector<S> dec_bias;             // dec.bias              y
  RowMatrix<S> pb;                // pb                    states x pb, row k = p_k

  // Every tensor zero (running_var too). Used as gradient storage.
  static HadynetParams zeros(const HadynetDims& dims);
  // PyTorch defaults: Linear weight and bias U(-1/sqrt(fan_in), +1/sqrt(fan_in));
  // LSTM weights and biases U(-1/sqrt(hidden), +1/sqrt(hidden)) (as torch.nn.LSTM);
  // BN weight 1, bias 0, running mean 0, running var 1; PB 0. Values are drawn
  // in double from std::mt19937_64(seed) in tensors() order, row-major, then
  // rounded to S, so initialized<float>(s) == initialized<double>(s).cast<float>().
  static HadynetParams initialized(const HadynetDims& dims, std::uint64_t seed);

  // All 13 tensors in a fixed order: enc.weight, enc.bias, enc_bn.weight,
  // enc_bn.bias, enc_bn.running_mean, enc_bn.running_var, lstm.weight_ih_l0,
  // lstm.weight_hh_l0, lstm.bias_ih_l0, lstm.bias_hh_l0, dec.weight, dec.bias, pb.
  std::vector<NamedTensor<S>> tensors();
  std::vector<NamedTensor<const S>> tensors() const;

  void set_zero();

  // Throws std::invalid_argument naming the first tensor whose shape does not
  // follow `dims` (or when `dims` is invalid).
  void check_shapes() const;

  // Element-wise conversion (float <-> double).
  template <class T>
  HadynetParams<T> cast() const {
    HadynetParams<T> out;
    out.dims = dims;
    out.enc_weight = enc_weight.template cast<T>();
    out.enc_bias = enc_bias.template cast<T>();
    out.enc_bn_weight = enc_bn_weight.template cast<T>();
    out.enc_bn_bias = enc_bn_bias.template cast<T>();
    out.enc_bn_running_mean = enc_bn_running_mean.template cast<T>();
    out.enc_bn_running_var = enc_bn_running_var.template cast<T>();
    out.lstm_weight_ih = lstm_weight_ih.template cast<T>();
    out.lstm_weight_hh = lstm_weight_hh.template cast<T>();
    out.lstm_bias_ih = lstm_bias_ih.template cast<T>();
    out.lstm_bias_hh = lstm_bias_hh.template cast<T>();
    out.dec_weight = dec_weight.template cast<T>();
    out.dec_bias = dec_bias.template cast<T>();
    out.pb = pb.template cast<T>();
    return out;
  }
};

extern template struct HadynetParams<float>;
extern template struct HadynetParams<double>;

}  // namespace hadynet::trainer
