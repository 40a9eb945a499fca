#include "trainer/pb_adaptation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hadynet::trainer {

namespace {

// The model's weights with a one-row PB table holding `pb`.
HadynetParams<float> single_pb_params(const HadynetModel& model, const Eigen::VectorXf& pb) {
  if (pb.size() != model.params.dims.pb) {
    throw std::invalid_argument("PB has " + std::to_string(pb.size()) + " values, the model " +
                                std::to_string(model.params.dims.pb));
  }
  HadynetParams<float> p = model.params;
  p.dims.states = 1;
  p.pb = pb.transpose();
  return p;
}

// Windows [first, first + count) of a batch (WindowBatch's step-major layout).
WindowBatch<float> window_range(const WindowBatch<float>& batch, const Matrix<float>& y, int first, int count,
                                Matrix<float>& y_out) {
  const int B = batch.windows(), N = batch.steps();
  WindowBatch<float> out;
  out.x0 = batch.x0.middleCols(first, count);
  out.u.resize(batch.u.rows(), static_cast<Eigen::Index>(N) * count);
  y_out.resize(y.rows(), static_cast<Eigen::Index>(N) * count);
  for (int k = 0; k < N; ++k) {
    out.u.middleCols(static_cast<Eigen::Index>(k) * count, count) =
        batch.u.middleCols(static_cast<Eigen::Index>(k) * B + first, count);
    y_out.middleCols(static_cast<Eigen::Index>(k) * count, count) =
        y.middleCols(static_cast<Eigen::Index>(k) * B + first, count);
  }
  out.state.assign(batch.state.begin() + first, batch.state.begin() + first + count);
  if (batch.pb.size() > 0) out.pb = batch.pb.middleCols(first, count);
  return out;
}

// The full-batch loss of a fit and its gradient, over the batch in chunks of
// AdaptOptions::windows_per_pass windows (a fit over the 40 000 windows of
// one long log took 3 GB in one pass), each weighted by its share of the
// windows. gradient() is taken at the point of the last loss()
// call: with one chunk, by the backward pass of that forward pass (as the
// unchunked fit did); with several, the chunks' forward and backward passes
// are run again there. loss() never changes the last gradient.
class ChunkedObjective {
 public:
  ChunkedObjective(const WindowBatch<float>& batch, const Matrix<float>& y, int windows_per_pass)
      : whole_(&batch), y_whole_(&y) {
    if (windows_per_pass < 1) throw std::invalid_argument("PB adaptation: windows_per_pass must be >= 1");
    const int B = batch.windows();
    if (B <= windows_per_pass) return;
    for (int first = 0; first < B; first += windows_per_pass) {
      const int count = std::min(windows_per_pass, B - first);
      targets_.emplace_back();
      chunks_.push_back(window_range(batch, y, first, count, targets_.back()));
      weights_.push_back(static_cast<double>(count) / static_cast<double>(B));
    }
  }

  double loss(const HadynetParams<float>& params) {
    if (chunks_.empty()) return static_cast<double>(mse_loss(net_.forward(params, *whole_, BnMode::kEval), *y_whole_, &d_y_));
    double total = 0;
    for (std::size_t i = 0; i < chunks_.size(); ++i)
      total += weights_[i] * static_cast<double>(mse_loss(net_.forward(params, chunks_[i], BnMode::kEval), targets_[i]));
    return total;
  }

  // dL/d(params) at the point of the last loss() call (PB rows summed over chunks; the other
  // groups are not used by the PB-only optimiser).
  const HadynetGrads<float>& gradient(const HadynetParams<float>& params) {
    if (chunks_.empty()) {
      net_.backward(params, d_y_, grads_);  // at `params`: the last forward was there
      return grads_;
    }
    Matrix<float> pb_sum = Matrix<float>::Zero(params.pb.rows(), params.pb.cols());
    for (std::size_t i = 0; i < chunks_.size(); ++i) {
      mse_loss(net_.forward(params, chunks_[i], BnMode::kEval), targets_[i], &d_y_);
      net_.backward(params, d_y_, grads_);
      pb_sum += static_cast<float>(weights_[i]) * grads_.params.pb;
    }
    grads_.params.pb = pb_sum;
    return grads_;
  }

 private:
  const WindowBatch<float>* whole_;
  const Matrix<float>* y_whole_;
  std::vector<WindowBatch<float>> chunks_;  // empty: one pass over the whole batch
  std::vector<Matrix<float>> targets_;
  std::vector<double> weights_;
  HadynetNetwork<float> net_;
  HadynetGrads<float> grads_;
  Matrix<float> d_y_;
};

// Full-batch MomentumSGD epochs on one gathered batch with the step-size
// safeguard (pb_adaptation.h); appends the loss before the first epoch and
// after each to `loss`. Returns the number of halvings. The rate is restored
// on return (the caller's optimiser keeps its configured rate).
int fit(HadynetParams<float>& params, MomentumSgd<float>& sgd, const WindowBatch<float>& batch,
        const Matrix<float>& y, const AdaptOptions& options, std::vector<double>& loss) {
  ChunkedObjective objective(batch, y, options.windows_per_pass);
  const double base_lr = sgd.options().lr;
  int halvings = 0;
  const std::size_t first = loss.size();
  double current = objective.loss(params);
  loss.push_back(current);
  for (int e = 0; e < options.epochs; ++e) {
    const HadynetGrads<float>& grads = objective.gradient(params);
    // The reference: the largest of the last kSafeguardWindow losses of this call.
    const std::size_t from = std::max(first, loss.size() - std::min<std::size_t>(loss.size() - first, kSafeguardWindow));
    const double reference = *std::max_element(loss.begin() + static_cast<long>(from), loss.end());
    const auto kept = params.pb;  // the PB before this epoch's step
    while (true) {
      sgd.step(params, grads.params);  // loss() below leaves the gradient as it is
      const double trial = objective.loss(params);
      if (std::isfinite(trial) && trial <= reference) {
        current = trial;
        break;
      }
      params.pb = kept;
      sgd.reset_momentum();
      if (halvings == kMaxHalvings) {  // no step keeps the loss down: stay
        current = objective.loss(params);
        break;
      }
      ++halvings;
      sgd.set_lr(sgd.options().lr * 0.5);
    }
    loss.push_back(current);
  }
  sgd.set_lr(base_lr);
  return halvings;
}

WindowBatch<float> single_state(WindowBatch<float> batch) {
  std::fill(batch.state.begin(), batch.state.end(), 0);
  return batch;
}

}  // namespace

AdaptResult adapt_pb_best_of(const HadynetModel& model, const WindowDataset& data, std::span<const int> ids,
                             const std::vector<Eigen::VectorXf>& starts, const AdaptOptions& options) {
  if (starts.empty()) throw std::invalid_argument("PB adaptation: no start PB");
  AdaptResult best;
  for (std::size_t i = 0; i < starts.size(); ++i) {
    AdaptResult r = adapt_pb(model, data, ids, starts[i], options);
    // A diverged fit (non-finite PB or loss) never wins over a finite one.
    const bool finite = r.pb.allFinite() && std::isfinite(r.loss.back());
    const bool best_finite = i > 0 && best.pb.allFinite() && std::isfinite(best.loss.back());
    if (i == 0 || (finite && (!best_finite || r.loss.back() < best.loss.back()))) best = std::move(r);
  }
  return best;
}

AdaptResult adapt_pb(const HadynetModel& model, const WindowDataset& data, std::span<const int> ids,
                     const Eigen::VectorXf& start, const AdaptOptions& options) {
  if (ids.empty()) throw std::invalid_argument("PB adaptation: no windows");
  HadynetParams<float> params = single_pb_params(model, start);
  MomentumSgd<float> sgd({options.lr, options.momentum}, GroupSet::only(ParamGroup::kPb));
  WindowBatch<float> batch;
  Matrix<float> y;
  data.gather(ids, batch, y);
  AdaptResult result;
  result.halvings = fit(params, sgd, single_state(std::move(batch)), y, options, result.loss);
  result.pb = params.pb.row(0).transpose();
  return result;
}

OnlinePbAdapter::OnlinePbAdapter(const HadynetModel& model, Eigen::VectorXf start, Options options)
    : model_(model),
      options_(options),
      pb_(std::move(start)),
      params_(single_pb_params(model, pb_)),
      sgd_({options.adapt.lr, options.adapt.momentum}, GroupSet::only(ParamGroup::kPb)),
      last_loss_(std::numeric_limits<double>::quiet_NaN()) {
  if (options.start_windows < 1 || options.max_windows < options.start_windows) {
    throw std::invalid_argument("online PB: need 1 <= start_windows <= max_windows");
  }
}

void OnlinePbAdapter::begin_segment() {
  rows_y_.clear();
  rows_u_.clear();
  segment_steps_ = 0;
}

bool OnlinePbAdapter::push(const Eigen::VectorXd& y, const Eigen::VectorXd& u) {
  const int N = model_.train_steps;
  rows_y_.push_back(y);
  rows_u_.push_back(u);
  ++segment_steps_;
  // Rows kept: x_i needs rows i-1 and i; the window then needs rows up to i+N.
  while (static_cast<int>(rows_y_.size()) > N + 2) {
    rows_y_.pop_front();
    rows_u_.pop_front();
  }
  // The window completed by this row starts at i = (this step) - N; it needs i >= 1.
  if (segment_steps_ - 1 - N < 1) return false;
  LogSequence rows;
  rows.y.resize(y.size(), N + 2);
  rows.u.resize(u.size(), N + 2);
  for (int t = 0; t < N + 2; ++t) {
    rows.y.col(t) = rows_y_[static_cast<std::size_t>(t)];
    rows.u.col(t) = rows_u_[static_cast<std::size_t>(t)];
  }
  // Row 1 of `rows` is x_i, rows 1..N are its commands, rows 2..N+1 its targets.
  x_.push_back(model_.norm.x.standardize(initial_state(model_.layout, rows, 1)).cast<float>());
  Matrix<float> wu(u.size(), N), wy(y.size(), N);
  for (int k = 0; k < N; ++k) {
    wu.col(k) = model_.norm.u.standardize(rows.u.col(1 + k)).cast<float>();
    wy.col(k) = model_.norm.y.standardize(rows.y.col(2 + k)).cast<float>();
  }
  u_.push_back(std::move(wu));
  y_.push_back(std::move(wy));
  if (windows() > options_.max_windows) {
    x_.pop_front();
    u_.pop_front();
    y_.pop_front();
  }
  if (windows() < options_.start_windows) return false;

  const Eigen::Index B = windows();
  WindowBatch<float> batch;
  Matrix<float> target(y.size(), N * B);
  batch.x0.resize(model_.params.dims.x, B);
  batch.u.resize(u.size(), N * B);
  batch.state.assign(static_cast<std::size_t>(B), 0);
  for (Eigen::Index b = 0; b < B; ++b) {
    const auto w = static_cast<std::size_t>(b);
    batch.x0.col(b) = x_[w];
    for (Eigen::Index k = 0; k < N; ++k) {
      batch.u.col(k * B + b) = u_[w].col(k);
      target.col(k * B + b) = y_[w].col(k);
    }
  }
  std::vector<double> loss;
  fit(params_, sgd_, batch, target, options_.adapt, loss);
  pb_ = params_.pb.row(0).transpose();
  last_loss_ = loss.back();
  return true;
}

}  // namespace hadynet::trainer
