// Joint training of the HADYNET weights and the PB table (docs/method.md,
// "Training"): shuffled windows, mini-batches, Adam, BN running statistics, a
// held-out loss per epoch, a checkpoint after every epoch.
//
// Determinism: for a seed and a thread count the run is bit-reproducible,
// and resuming from a checkpoint continues exactly as if never stopped (the
// order of epoch e is a function of (seed, e) only).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/optim.h"
#include "trainer/window_dataset.h"

namespace hadynet::trainer {

struct TrainOptions {
  int epochs = 200;         // paper: N_epoch^train = 200
  int batch = 100;          // paper: N_batch^train = 100
  double lr = 1e-3;         // Adam
  std::uint64_t seed = 1;   // weights and shuffling
  bool variable_pb = true;  // false: the PB table stays 0 ("constant PB" ablation)
};

struct EpochStats {
  int epoch = 0;                 // 1-based
  double train_loss = 0.0;       // mean of the batch losses (BN training mode)
  double held_out_loss = std::numeric_limits<double>::quiet_NaN();  // BN eval; NaN: no held-out data
  double seconds = 0.0;          // wall time of the epoch
};

// What a checkpoint holds besides the model.
struct TrainingState {
  int epochs_done = 0;
  Adam<float>::State adam;
  std::vector<EpochStats> history;
};

// A freshly initialised model for a dataset: PyTorch default initialisation
// from `seed`, PB table of `states.size()` zero rows.
HadynetModel new_model(const FeatureLayout& layout, const Normalization& norm,
                       std::vector<PbState> states, int pb_dim, int hidden, int train_steps,
                       std::uint64_t seed);

// Mean squared error (standardised units) of `model` on the windows `ids`,
// BN in eval mode, each window with its own state's PB (or with `pb` for all
// windows if it is non-empty). Evaluated in chunks of `chunk` windows.
double evaluate_loss(const HadynetModel& model, const WindowDataset& data, std::span<const int> ids,
                     const Eigen::VectorXf& pb = {}, int chunk = 1000);

// The same per y channel: element c is channel c's mean squared error
// (standardised units) over the windows' steps; their mean is evaluate_loss's
// value up to rounding (evaluate_loss sums in its own order: training's
// reported losses keep their bits).
// Empty `ids`: a vector of NaN.
Eigen::VectorXd evaluate_channel_loss(const HadynetModel& model, const WindowDataset& data,
                                      std::span<const int> ids, const Eigen::VectorXf& pb = {}, int chunk = 1000);

// Runs epochs state.epochs_done+1 .. options.epochs on the `train` windows,
// reporting each epoch (held-out loss on `held_out` if non-empty) to
// `on_epoch`, which may save a checkpoint. Throws std::invalid_argument on
// option or size errors.
void train(HadynetModel& model, TrainingState& state, const WindowDataset& data,
           std::span<const int> train_ids, std::span<const int> held_out_ids,
           const TrainOptions& options, const std::function<void(const EpochStats&)>& on_epoch);

// The window order of epoch `epoch` (1-based): a permutation of `ids` that
// depends only on (seed, epoch).
std::vector<int> epoch_order(std::span<const int> ids, std::uint64_t seed, int epoch);

}  // namespace hadynet::trainer
