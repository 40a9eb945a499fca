// Fine-tuning for `hadynet residual --fix` (docs/residual.md): a few epochs
// from the current weights on the training part of the analysed logs.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "trainer/hadynet_model.h"

namespace hadynet::trainer::residual {

struct FineTuneOptions {
  int epochs = 20;         // from the current weights
  int batch = 100;         // windows per Adam step
  double lr = 1e-3;        // Adam
  std::uint64_t seed = 1;  // window order: epoch_order(seed, epoch)
  // The u columns whose LSTM input weights (lstm_weight_ih) an augmentation
  // has just added at zero (its derived inputs: augmented_model), and their
  // learning rate as a multiple of lr. Adam moves a weight by at most about
  // lr per step, so 20 epochs of a few batches take a weight from zero to
  // about 0.1 at most, while the trained weights only need adjusting.
  std::vector<int> added_u_columns;
  double added_input_lr_scale = 1.0;
};

// Adds a PB row for every state of `seqs` the model does not know, started
// from `pb_of_seq` of its first sequence; returns each sequence's row.
std::vector<int> ensure_states(HadynetModel& model, const std::vector<LogSequence>& seqs,
                               const std::vector<Eigen::VectorXf>& pb_of_seq);

// Fine-tunes `model` on every window of `seqs` (state rows `state_rows`)
// with batch norm frozen (eval mode: the running statistics of the original
// training data stay; with a few hundred windows, batch statistics would move
// them and hurt every channel); Adam on every weight and the PB table
// (options.added_u_columns' input weights at added_input_lr_scale times lr). The
// loss is that of the clipped output (a clipped element has zero gradient;
// output_clip.h). Re-measures the value ranges on the windows and drops the
// detection calibration (it belongs to the old weights). Returns the loss
// per epoch (standardised) and sets *windows. Throws std::runtime_error for
// fewer than 2 windows or a loss that is not finite, std::invalid_argument
// for an added column outside the model's u.
std::vector<double> fine_tune(HadynetModel& model, const std::vector<LogSequence>& seqs,
                              const std::vector<int>& state_rows, const FineTuneOptions& options, long* windows);

}  // namespace hadynet::trainer::residual
