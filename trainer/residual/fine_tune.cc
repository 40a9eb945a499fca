#include "trainer/residual/fine_tune.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <span>
#include <stdexcept>

#include "trainer/deploy_prep.h"
#include "trainer/hadynet_network.h"
#include "trainer/optim.h"
#include "trainer/output_clip.h"
#include "trainer/training.h"
#include "trainer/window_dataset.h"

namespace hadynet::trainer::residual {

std::vector<int> ensure_states(HadynetModel& model, const std::vector<LogSequence>& seqs,
                               const std::vector<Eigen::VectorXf>& pb_of_seq) {
  std::vector<int> rows;
  for (std::size_t i = 0; i < seqs.size(); ++i) {
    int k = model.state_index(seqs[i].state);
    if (k < 0) {
      k = static_cast<int>(model.states.size());
      model.states.push_back({seqs[i].state, seqs[i].object});
      model.params.pb.conservativeResize(k + 1, model.params.dims.pb);
      model.params.pb.row(k) = pb_of_seq[i].transpose();
      model.params.dims.states = k + 1;
    }
    rows.push_back(k);
  }
  return rows;
}

std::vector<Eigen::MatrixXd> reading_loss_weights(const SensorModel& sensor, const std::vector<std::string>& y_names,
                                                  const std::vector<LogSequence>& seqs) {
  std::vector<Eigen::MatrixXd> weights;
  if (sensor.curves.empty()) return weights;
  for (const LogSequence& seq : seqs) {
    Eigen::MatrixXd w = Eigen::MatrixXd::Ones(seq.y.rows(), seq.y.cols());
    for (const SensorCurve& curve : sensor.curves) {
      const auto c = std::find(y_names.begin(), y_names.end(), curve.channel) - y_names.begin();
      if (c >= seq.y.rows()) continue;
      for (Eigen::Index t = 0; t < seq.y.cols(); ++t) w(c, t) = std::pow(curve_slope(curve, seq.y(c, t)), 2);
    }
    weights.push_back(std::move(w));
  }
  return weights;
}

std::vector<double> fine_tune(HadynetModel& model, const std::vector<LogSequence>& seqs,
                              const std::vector<int>& state_rows, const FineTuneOptions& o, long* windows,
                              const std::vector<Eigen::MatrixXd>& weights, FineTuneState* resume) {
  if (!weights.empty() && weights.size() != seqs.size())
    throw std::invalid_argument("fine_tune: one weight matrix per sequence expected");
  const WindowDataset data(seqs, state_rows, model.layout, model.norm, model.train_steps);
  std::vector<int> ids(static_cast<std::size_t>(data.size()));
  std::iota(ids.begin(), ids.end(), 0);
  if (ids.size() < 2) throw std::runtime_error("--fix: the training part of the logs holds fewer than 2 windows");
  Adam<float> adam(Adam<float>::Options{o.lr, 0.9, 0.999, 1e-8}, GroupSet::all().without(ParamGroup::kEncoderBn));
  if (resume != nullptr && !resume->adam.t.empty()) adam.set_state(resume->adam);
  HadynetNetwork<float> net;
  HadynetGrads<float> grads;
  WindowBatch<float> batch;
  Matrix<float> y, y_hat, d_y, w;
  std::vector<double> history;
  const auto batch_size = static_cast<std::size_t>(std::max(1, o.batch));
  for (int epoch = o.first_epoch; epoch < o.first_epoch + o.epochs; ++epoch) {
    const std::vector<int> order = epoch_order(ids, o.seed, epoch);
    double sum = 0;
    int batches = 0;
    for (std::size_t begin = 0; begin < order.size(); begin += batch_size) {
      const std::size_t n = std::min(batch_size, order.size() - begin);
      data.gather(std::span<const int>(order).subspan(begin, n), batch, y);
      // The loss of the clipped output (saturation; no clips: the plain loss).
      y_hat = net.forward(model.params, batch, BnMode::kEval);
      clip_standardised(model, y_hat);
      if (weights.empty()) {
        sum += static_cast<double>(mse_loss(y_hat, y, &d_y));
      } else {  // y is step-major (WindowDataset::gather): column k n + b is step k of window b
        const std::span<const int> ids_of_batch = std::span<const int>(order).subspan(begin, n);
        w.resize(y.rows(), y.cols());
        for (std::size_t b = 0; b < n; ++b) {
          const WindowDataset::Window& win = data.window(ids_of_batch[b]);
          const Eigen::MatrixXd& of_seq = weights[static_cast<std::size_t>(win.sequence)];
          for (int k = 0; k < data.steps(); ++k)
            w.col(k * static_cast<Eigen::Index>(n) + static_cast<Eigen::Index>(b)) =
                of_seq.col(win.start + k + 1).cast<float>();
        }
        const auto count = static_cast<float>(y.size());
        d_y = (2.0F / count) * (w.array() * (y_hat - y).array()).matrix();
        sum += static_cast<double>((w.array() * (y_hat - y).array().square()).sum() / count);
      }
      clip_standardised(model, y_hat, &d_y);  // zero gradient where clipped
      net.backward(model.params, d_y, grads);
      adam.step(model.params, grads.params);
      ++batches;
    }
    history.push_back(sum / batches);
    if (!std::isfinite(history.back())) throw std::runtime_error("--fix: fine-tuning diverged (loss not finite)");
  }
  if (resume != nullptr) resume->adam = adam.state();
  ValueRanges ranges = measure_ranges(model, data, ids);
  ranges.source = "hadynet residual --fix: training part of " + std::to_string(seqs.size()) + " logs";
  model.ranges = ranges;
  model.detection.reset();  // calibrated with the old weights
  if (windows != nullptr) *windows = static_cast<long>(ids.size());
  return history;
}

}  // namespace hadynet::trainer::residual
