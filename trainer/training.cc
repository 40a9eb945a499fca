#include "trainer/training.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hadynet::trainer {

namespace {

std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

HadynetModel new_model(const FeatureLayout& layout, const Normalization& norm,
                       std::vector<PbState> states, int pb_dim, int hidden, int train_steps,
                       std::uint64_t seed) {
  HadynetModel model;
  model.layout = layout;
  model.profile.delta_groups = layout.delta_groups;
  model.norm = norm;
  HadynetDims dims;
  dims.x = static_cast<int>(layout.x_names.size());
  dims.u = static_cast<int>(layout.u_names.size());
  dims.y = static_cast<int>(layout.y_names.size());
  dims.pb = pb_dim;
  dims.hidden = hidden;
  dims.states = static_cast<int>(states.size());
  validate(dims);
  model.params = HadynetParams<float>::initialized(dims, seed);
  model.states = std::move(states);
  model.train_steps = train_steps;
  model.check_consistent();
  return model;
}

std::vector<int> epoch_order(std::span<const int> ids, std::uint64_t seed, int epoch) {
  std::vector<int> order(ids.begin(), ids.end());
  std::uint64_t state = seed * 0x2545f4914f6cdd1dULL + static_cast<std::uint64_t>(epoch);
  for (std::size_t i = order.size(); i > 1; --i) {
    // Unbiased enough for shuffling: 64-bit draw modulo i (i < 2^32).
    const std::size_t j = static_cast<std::size_t>(splitmix64(state) % i);
    std::swap(order[i - 1], order[j]);
  }
  return order;
}

namespace {

// Runs `model` (BN eval) on the windows `ids` in chunks of `chunk` windows,
// each with its own state's PB or with `pb` if it is non-empty, and calls
// on_chunk(y_hat, y) per chunk (both y_dim x (steps * windows)). `caller`
// names the function in the chunk error.
template <class OnChunk>
void for_each_chunk(const HadynetModel& model, const WindowDataset& data, std::span<const int> ids,
                    const Eigen::VectorXf& pb, int chunk, const char* caller, OnChunk on_chunk) {
  if (chunk < 1) throw std::invalid_argument(std::string(caller) + ": chunk must be >= 1");
  HadynetNetwork<float> net;
  WindowBatch<float> batch;
  Matrix<float> y;
  for (std::size_t begin = 0; begin < ids.size(); begin += static_cast<std::size_t>(chunk)) {
    const std::size_t n = std::min(ids.size() - begin, static_cast<std::size_t>(chunk));
    data.gather(ids.subspan(begin, n), batch, y);
    if (pb.size() != 0) batch.pb = pb.replicate(1, static_cast<Eigen::Index>(n));
    on_chunk(net.forward(model.params, batch, BnMode::kEval), y);
  }
}

}  // namespace

Eigen::VectorXd evaluate_channel_loss(const HadynetModel& model, const WindowDataset& data,
                                      std::span<const int> ids, const Eigen::VectorXf& pb, int chunk) {
  if (ids.empty()) return Eigen::VectorXd::Constant(data.y_dim(), std::numeric_limits<double>::quiet_NaN());
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(data.y_dim());
  for_each_chunk(model, data, ids, pb, chunk, "evaluate_channel_loss",
                 [&](const Matrix<float>& y_hat, const Matrix<float>& y) {
                   sum += (y_hat - y).rowwise().squaredNorm().cast<double>();
                 });
  return sum / (static_cast<double>(ids.size()) * data.steps());
}

double evaluate_loss(const HadynetModel& model, const WindowDataset& data, std::span<const int> ids,
                     const Eigen::VectorXf& pb, int chunk) {
  if (ids.empty()) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0.0;
  for_each_chunk(model, data, ids, pb, chunk, "evaluate_loss", [&](const Matrix<float>& y_hat, const Matrix<float>& y) {
    sum += static_cast<double>((y_hat - y).squaredNorm());
  });
  return sum / (static_cast<double>(ids.size()) * data.steps() * data.y_dim());
}

void train(HadynetModel& model, TrainingState& state, const WindowDataset& data,
           std::span<const int> train_ids, std::span<const int> held_out_ids,
           const TrainOptions& options, const std::function<void(const EpochStats&)>& on_epoch) {
  if (options.batch < 2) throw std::invalid_argument("batch size must be >= 2 (batch norm)");
  if (options.epochs < 1) throw std::invalid_argument("epochs must be >= 1");
  if (train_ids.size() < 2) throw std::invalid_argument("fewer than 2 training windows");
  if (data.steps() != model.train_steps) {
    throw std::invalid_argument("windows have " + std::to_string(data.steps()) +
                                " steps, the model trains on " +
                                std::to_string(model.train_steps));
  }
  GroupSet trainable = GroupSet::all();
  if (!options.variable_pb) trainable = trainable.without(ParamGroup::kPb);
  Adam<float> adam(Adam<float>::Options{options.lr, 0.9, 0.999, 1e-8}, trainable);
  adam.set_state(state.adam);

  HadynetNetwork<float> net;
  HadynetGrads<float> grads;
  WindowBatch<float> batch;
  Matrix<float> y;
  Matrix<float> d_y;
  const auto batch_size = static_cast<std::size_t>(options.batch);
  for (int epoch = state.epochs_done + 1; epoch <= options.epochs; ++epoch) {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<int> order = epoch_order(train_ids, options.seed, epoch);
    double loss_sum = 0.0;
    int batches = 0;
    for (std::size_t begin = 0; begin < order.size(); begin += batch_size) {
      const std::size_t n = std::min(batch_size, order.size() - begin);
      if (n < 2) break;  // a last batch of one window cannot be batch-normalised
      data.gather(std::span<const int>(order).subspan(begin, n), batch, y);
      const Matrix<float>& y_hat = net.forward(model.params, batch, BnMode::kTrain);
      loss_sum += static_cast<double>(mse_loss(y_hat, y, &d_y));
      net.backward(model.params, d_y, grads);
      adam.step(model.params, grads.params);
      net.update_bn_running_stats(model.params);
      ++model.bn_batches_tracked;
      ++batches;
    }
    EpochStats stats;
    stats.epoch = epoch;
    stats.train_loss = loss_sum / batches;
    stats.held_out_loss = evaluate_loss(model, data, held_out_ids);
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.epochs_done = epoch;
    state.adam = adam.state();
    state.history.push_back(stats);
    if (!std::isfinite(stats.train_loss)) {
      throw std::runtime_error("training diverged at epoch " + std::to_string(epoch) +
                               " (loss not finite); try a smaller --lr");
    }
    on_epoch(stats);
  }
}

}  // namespace hadynet::trainer
