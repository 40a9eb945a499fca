// Fine-tuning for `hadynet residual --fix` (docs/residual.md): a few epochs
// from the current weights on the training part of the analysed logs.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/optim.h"

namespace hadynet::trainer::residual {

struct FineTuneOptions {
  int epochs = 20;         // from the current weights
  int batch = 100;         // windows per Adam step
  double lr = 1e-3;        // Adam
  std::uint64_t seed = 1;  // window order: epoch_order(seed, epoch)
  // The first epoch's number (epochs first_epoch .. first_epoch + epochs - 1):
  // a fine-tuning continued after k epochs starts at k + 1, so its windows
  // come in the order the uninterrupted run's later epochs would take.
  int first_epoch = 1;
};

// Where a fine-tuning stopped: the optimiser's moments and step counts
// (Adam::State). fine_tune() given one continues from it (none yet: it
// starts afresh) and leaves its own end there, so a fine-tuning run in
// parts (the data re-read between them, FineTuneOptions::first_epoch
// numbering the epochs on) is the same as one run where nothing changed
// between the parts.
struct FineTuneState {
  Adam<float>::State adam;
};

// Adds a PB row for every state of `seqs` the model does not know, started
// from `pb_of_seq` of its first sequence; returns each sequence's row.
std::vector<int> ensure_states(HadynetModel& model, const std::vector<LogSequence>& seqs,
                               const std::vector<Eigen::VectorXf>& pb_of_seq);

// The weight of each target element of `seqs` (one matrix per sequence,
// the shape of its y) that makes the fine-tuning loss, in the model's frame,
// the loss of the readings to first order: a channel read through a curve g
// (sensor.curves) weighs g'(level)^2 at its target's level (an error e in
// the level is g'(level) e in the reading); every other element weighs 1.
// Empty when the sensor model has no curve (every weight 1).
std::vector<Eigen::MatrixXd> reading_loss_weights(const SensorModel& sensor, const std::vector<std::string>& y_names,
                                                  const std::vector<LogSequence>& seqs);

// Fine-tunes `model` on every window of `seqs` (state rows `state_rows`)
// with batch norm frozen (eval mode: the running statistics of the original
// training data stay; with a few hundred windows, batch statistics would move
// them and hurt every channel); Adam on every weight and the PB table. The
// loss is that of the clipped output (a clipped element has zero gradient;
// output_clip.h). Re-measures the value ranges on the windows and drops the
// detection calibration (it belongs to the old weights). Returns the loss
// per epoch (standardised) and sets *windows. `weights` (empty: all 1, or
// reading_loss_weights(); each of y's shape) weighs each target element's
// squared error. Throws std::invalid_argument when `weights` is neither
// empty nor one matrix per sequence, std::runtime_error for fewer than 2
// windows or a loss that is not finite. `resume` (nullptr: a fresh
// optimiser): the optimiser's state to continue from, set to its end.
std::vector<double> fine_tune(HadynetModel& model, const std::vector<LogSequence>& seqs,
                              const std::vector<int>& state_rows, const FineTuneOptions& options, long* windows,
                              const std::vector<Eigen::MatrixXd>& weights = {}, FineTuneState* resume = nullptr);

}  // namespace hadynet::trainer::residual
