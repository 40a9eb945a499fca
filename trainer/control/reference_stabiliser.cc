#include "trainer/control/reference_stabiliser.h"

#include <stdexcept>

#include "trainer/hadynet_network.h"

namespace hadynet::trainer::control {

StabiliserPlan reference_plan(const HadynetParams<double>& params, const StabiliserProblem& problem,
                              const LossWeights& weights, const StabiliserSettings& settings) {
  const HadynetDims& d = params.dims;
  const int hc = settings.horizon, nu = d.u, ny = d.y;
  if (problem.x0.size() != d.x || problem.pb.size() != d.pb || problem.y_now.size() != ny ||
      problem.y_ref.size() != ny || problem.hold.size() != nu || weights.up.size() != ny ||
      weights.down.size() != ny || static_cast<int>(settings.active.size()) != nu || hc < 1) {
    throw std::invalid_argument("reference_plan: sizes do not match the model");
  }
  WindowBatch<double> batch;
  batch.x0 = problem.x0;
  batch.pb = problem.pb;
  batch.u = problem.hold.replicate(1, hc);
  HadynetNetwork<double> net;
  const Eigen::MatrixXd y_hold = net.forward(params, batch, BnMode::kEval);
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
    const double current = loss_and_dy(net.forward(params, batch, BnMode::kEval), &dy);
    HadynetGrads<double> grads;
    net.backward(params, dy, grads, settings.truncation);
    for (int i = 0; i < nu; ++i)
      if (!settings.active[static_cast<std::size_t>(i)]) grads.u.row(i).setZero();
    const Eigen::MatrixXd unit = grads.u / grads.u.norm();
    if (epoch == 0) p.direction = Eigen::Map<const Eigen::VectorXd>(unit.data(), unit.size());
    // Monotone line search: a step is taken only if it lowers L.
    Eigen::MatrixXd best_u = batch.u;
    double best = current;
    p.alpha = -1;
    for (std::size_t a = 0; a < settings.alphas.size(); ++a) {
      WindowBatch<double> candidate = batch;
      candidate.u = batch.u - settings.alphas[a] * unit;
      const double l = loss_and_dy(net.forward(params, candidate, BnMode::kEval), nullptr);
      if (l < best) {
        best = l;
        best_u = candidate.u;
        p.alpha = static_cast<int>(a);
      }
    }
    batch.u = best_u;
    if (p.alpha < 0) break;
  }
  p.command = batch.u.col(0);
  return p;
}

}  // namespace hadynet::trainer::control
