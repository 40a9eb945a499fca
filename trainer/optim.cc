#include "trainer/optim.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hadynet::trainer {

namespace {

template <class S>
using ConstArrayMap = Eigen::Map<const Eigen::Array<S, Eigen::Dynamic, 1>>;
template <class S>
using ArrayMap = Eigen::Map<Eigen::Array<S, Eigen::Dynamic, 1>>;

// Pairs of (parameter, gradient) views; throws if the shapes differ.
template <class S>
void check_same_shapes(const std::vector<NamedTensor<S>>& params,
                       const std::vector<NamedTensor<const S>>& grads) {
  if (params.size() != grads.size()) throw std::invalid_argument("optimiser: tensor count differs");
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (params[i].rows != grads[i].rows || params[i].cols != grads[i].cols) {
      throw std::invalid_argument(
          "optimiser: gradient of " + std::string(params[i].name) + " is " +
          std::to_string(grads[i].rows) + "x" + std::to_string(grads[i].cols) + ", parameter is " +
          std::to_string(params[i].rows) + "x" + std::to_string(params[i].cols));
    }
  }
}

template <class S>
bool updates(const NamedTensor<S>& t, GroupSet trainable) {
  return t.trainable && trainable.contains(t.group);
}

}  // namespace

template <class S>
Adam<S>::Adam(Options options, GroupSet trainable) : options_(options), trainable_(trainable) {}

template <class S>
void Adam<S>::step(HadynetParams<S>& params, const HadynetParams<S>& grads) {
  std::vector<NamedTensor<S>> p = params.tensors();
  const std::vector<NamedTensor<const S>> g = grads.tensors();
  check_same_shapes(p, g);
  m_.resize(p.size());
  v_.resize(p.size());
  t_.resize(p.size(), 0);
  const S b1 = static_cast<S>(options_.beta1);
  const S b2 = static_cast<S>(options_.beta2);
  const S eps = static_cast<S>(options_.eps);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!updates(p[i], trainable_)) continue;
    const int n = p[i].size();
    if (m_[i].size() != n) {
      m_[i] = Vector<S>::Zero(n);
      v_[i] = Vector<S>::Zero(n);
      t_[i] = 0;
    }
    const long t = ++t_[i];
    const double bias1 = 1.0 - std::pow(options_.beta1, static_cast<double>(t));
    const double bias2 = 1.0 - std::pow(options_.beta2, static_cast<double>(t));
    const S step_size = static_cast<S>(options_.lr / bias1);
    const S sqrt_bias2 = static_cast<S>(std::sqrt(bias2));
    ArrayMap<S> param(p[i].data, n);
    const ConstArrayMap<S> grad(g[i].data, n);
    auto m = m_[i].array();
    auto v = v_[i].array();
    m = b1 * m + (S(1) - b1) * grad;
    v = b2 * v + (S(1) - b2) * grad.square();
    param -= step_size * m / (v.sqrt() / sqrt_bias2 + eps);
  }
}

template <class S>
MomentumSgd<S>::MomentumSgd(Options options, GroupSet trainable)
    : options_(options), trainable_(trainable) {}

template <class S>
void MomentumSgd<S>::step(HadynetParams<S>& params, const HadynetParams<S>& grads) {
  std::vector<NamedTensor<S>> p = params.tensors();
  const std::vector<NamedTensor<const S>> g = grads.tensors();
  check_same_shapes(p, g);
  buf_.resize(p.size());
  const S lr = static_cast<S>(options_.lr);
  const S momentum = static_cast<S>(options_.momentum);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!updates(p[i], trainable_)) continue;
    const int n = p[i].size();
    if (buf_[i].size() != n) buf_[i] = Vector<S>::Zero(n);
    ArrayMap<S> param(p[i].data, n);
    const ConstArrayMap<S> grad(g[i].data, n);
    auto buf = buf_[i].array();
    buf = momentum * buf + grad;
    param -= lr * buf;
  }
}

template class Adam<float>;
template class Adam<double>;
template class MomentumSgd<float>;
template class MomentumSgd<double>;

}  // namespace hadynet::trainer
