#include "trainer/control/reference_stabiliser.h"

#include <algorithm>
#include <stdexcept>

#include "trainer/derived_inputs.h"
#include "trainer/hadynet_network.h"

namespace hadynet::trainer::control {

std::vector<LaggedInput> lagged_inputs(const HadynetModel& model) {
  const std::vector<std::string>& u = model.layout.u_names;
  std::vector<LaggedInput> out;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const auto d = parse_derived_input(u[i]);
    if (!d || d->kind != DerivedKind::kLag) continue;
    const auto b = std::find(u.begin(), u.end(), d->base);
    if (b == u.end()) throw std::invalid_argument("lag input " + u[i] + ": its base " + d->base + " is not a command");
    LaggedInput l;
    l.slot = static_cast<int>(i);
    l.base = static_cast<int>(b - u.begin());
    l.lag = d->lag;
    const Eigen::VectorXd& mean = model.norm.u.mean;
    const Eigen::VectorXd& sd = model.norm.u.std;
    l.scale = sd(l.base) / sd(l.slot);
    l.offset = (mean(l.base) - mean(l.slot)) / sd(l.slot);
    l.history = Eigen::VectorXd::Constant(l.lag, -mean(l.slot) / sd(l.slot));  // the command 0
    out.push_back(std::move(l));
  }
  return out;
}

namespace {

// The network's inputs of plan `u` (U x horizon): u with each lag input
// filled in from its base (LaggedInput).
Eigen::MatrixXd network_inputs(const Eigen::MatrixXd& u, const std::vector<LaggedInput>& lagged) {
  Eigen::MatrixXd in = u;
  for (const LaggedInput& l : lagged)
    for (Eigen::Index k = 0; k < u.cols(); ++k)
      in(l.slot, k) = k < l.lag ? l.history(k) : l.scale * u(l.base, k - l.lag) + l.offset;
  return in;
}

// dL/du of the plan from dL/d(network inputs): each lag input's gradient
// goes to its base command lag steps earlier, none to the lag slot.
void fold_lag_gradients(Eigen::MatrixXd& g, const std::vector<LaggedInput>& lagged) {
  for (const LaggedInput& l : lagged) {
    for (Eigen::Index k = l.lag; k < g.cols(); ++k) g(l.base, k - l.lag) += l.scale * g(l.slot, k);
    g.row(l.slot).setZero();
  }
}

}  // namespace

StabiliserPlan reference_plan(const HadynetParams<double>& params, const StabiliserProblem& problem,
                              const LossWeights& weights, const StabiliserSettings& settings) {
  const HadynetDims& d = params.dims;
  const int hc = settings.horizon, nu = d.u, ny = d.y;
  if (problem.x0.size() != d.x || problem.pb.size() != d.pb || problem.y_now.size() != ny ||
      problem.y_ref.size() != ny || problem.hold.size() != nu || weights.up.size() != ny ||
      weights.down.size() != ny || static_cast<int>(settings.active.size()) != nu || hc < 1) {
    throw std::invalid_argument("reference_plan: sizes do not match the model");
  }
  for (const LaggedInput& l : problem.lagged) {
    if (l.slot < 0 || l.slot >= nu || l.base < 0 || l.base >= nu || l.lag < 1 || l.history.size() != l.lag)
      throw std::invalid_argument("reference_plan: a lag input does not match the model");
  }
  WindowBatch<double> batch;
  batch.x0 = problem.x0;
  batch.pb = problem.pb;
  Eigen::MatrixXd plan = problem.hold.replicate(1, hc);
  HadynetNetwork<double> net;
  const auto predict = [&](const Eigen::MatrixXd& u) {
    batch.u = network_inputs(u, problem.lagged);
    return net.forward(params, batch, BnMode::kEval);
  };
  const Eigen::MatrixXd y_hold = predict(plan);
  const Eigen::MatrixXd ref = y_hold.colwise() + (problem.y_ref - problem.y_now);
  const auto loss_and_dy = [&](const Eigen::MatrixXd& y, Eigen::MatrixXd* dy) {
    double l = 0;
    if (dy) dy->resize(ny, hc);
    for (int k = 0; k < hc; ++k) {
      for (int i = 0; i < ny; ++i) {
        const double e = y(i, k) - ref(i, k);
        const double w = e >= 0 ? weights.up(i) : weights.down(i);
        l += w * e * e;
        if (dy) (*dy)(i, k) = 2 * w * e;
      }
    }
    return l;
  };
  StabiliserPlan p;
  for (int epoch = 0; epoch < settings.epochs; ++epoch) {
    Eigen::MatrixXd dy;
    const double current = loss_and_dy(predict(plan), &dy);
    HadynetGrads<double> grads;
    net.backward(params, dy, grads, settings.truncation);
    fold_lag_gradients(grads.u, problem.lagged);
    for (int i = 0; i < nu; ++i)
      if (!settings.active[static_cast<std::size_t>(i)]) grads.u.row(i).setZero();
    const Eigen::MatrixXd unit = grads.u / grads.u.norm();
    if (epoch == 0) p.direction = Eigen::Map<const Eigen::VectorXd>(unit.data(), unit.size());
    // Monotone line search: a step is taken only if it lowers L.
    Eigen::MatrixXd best_u = plan;
    double best = current;
    p.alpha = -1;
    for (std::size_t a = 0; a < settings.alphas.size(); ++a) {
      const Eigen::MatrixXd candidate = plan - settings.alphas[a] * unit;
      const double l = loss_and_dy(predict(candidate), nullptr);
      if (l < best) {
        best = l;
        best_u = candidate;
        p.alpha = static_cast<int>(a);
      }
    }
    plan = best_u;
    if (p.alpha < 0) break;
  }
  // The first step's inputs: the command, and the derived inputs as used.
  p.command = network_inputs(plan, problem.lagged).col(0);
  return p;
}

}  // namespace hadynet::trainer::control
