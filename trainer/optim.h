// Optimisers over HadynetParams: Adam for training weights and PB jointly,
// MomentumSGD for PB-only adaptation (docs/method.md, "Training" and "PB adaptation"). Each updates only
// the trainable tensors (not BN running statistics) of its `trainable`
// groups; the tensors of other groups are frozen: neither they nor any
// optimiser state of theirs change.
#pragma once

#include <utility>
#include <vector>

#include "trainer/hadynet_params.h"

namespace hadynet::trainer {

// torch.optim.Adam (no weight decay, no AMSGrad), per element, t = number of
// steps this tensor has been updated:
//   m = b1 m + (1 - b1) g;  v = b2 v + (1 - b2) g^2
//   p -= lr / (1 - b1^t) * m / (sqrt(v) / sqrt(1 - b2^t) + eps)
template <class S>
class Adam {
 public:
  struct Options {
    double lr = 1e-3;
    double beta1 = 0.9;
    double beta2 = 0.999;
    double eps = 1e-8;
  };

  explicit Adam(Options options, GroupSet trainable = GroupSet::all());

  // `grads` must have the shapes of `params` (e.g. HadynetGrads::params).
  // Throws std::invalid_argument otherwise.
  void step(HadynetParams<S>& params, const HadynetParams<S>& grads);

  void set_trainable(GroupSet trainable) { trainable_ = trainable; }
  GroupSet trainable() const { return trainable_; }
  const Options& options() const { return options_; }

  // Moments and step counts per tensor (tensors() order; a tensor never
  // updated has empty m, v and t 0). Saved in checkpoints to resume exactly.
  struct State {
    std::vector<Vector<S>> m, v;
    std::vector<long> t;
  };
  State state() const { return State{m_, v_, t_}; }
  void set_state(State state) {
    m_ = std::move(state.m);
    v_ = std::move(state.v);
    t_ = std::move(state.t);
  }

 private:
  Options options_;
  GroupSet trainable_;
  std::vector<Vector<S>> m_;  // per tensor (tensors() order); empty until first update
  std::vector<Vector<S>> v_;
  std::vector<long> t_;
};

// Momentum SGD (Chainer MomentumSGD; same iterates as torch.optim.SGD with
// momentum, no dampening, no Nesterov, constant lr), per element:
//   buf = momentum * buf + g   (buf starts at 0);   p -= lr * buf
// Defaults: lr 0.01, momentum 0.9, only the PB table trainable.
template <class S>
class MomentumSgd {
 public:
  struct Options {
    double lr = 0.01;
    double momentum = 0.9;
  };

  explicit MomentumSgd(Options options, GroupSet trainable = GroupSet::only(ParamGroup::kPb));

  void step(HadynetParams<S>& params, const HadynetParams<S>& grads);

  void set_trainable(GroupSet trainable) { trainable_ = trainable; }
  GroupSet trainable() const { return trainable_; }
  const Options& options() const { return options_; }
  // For a step-size safeguard (pb_adaptation.cc): a new rate, and forgetting
  // the velocity of rejected steps.
  void set_lr(double lr) { options_.lr = lr; }
  void reset_momentum() { buf_.clear(); }

 private:
  Options options_;
  GroupSet trainable_;
  std::vector<Vector<S>> buf_;  // per tensor; empty until first update
};

extern template class Adam<float>;
extern template class Adam<double>;
extern template class MomentumSgd<float>;
extern template class MomentumSgd<double>;

}  // namespace hadynet::trainer
