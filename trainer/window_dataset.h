// Training windows (docs/method.md, "Windows and standardisation"): one per time step i of each log,
//   { x_i, u_[i, i+N), y_[i+1, i+N+1) },   1 <= i <= T-1-N,
// standardised and stored as float, gathered into WindowBatch batches.
#pragma once

#include <span>
#include <vector>

#include "trainer/hadynet_network.h"
#include "trainer/log_dataset.h"
#include "trainer/normalization.h"

namespace hadynet::trainer {

class WindowDataset {
 public:
  struct Window {
    int sequence;  // index into the sequences given to the constructor
    int start;     // i: x_i is the window's initial state
  };

  // `state_of_sequence[s]` is the PB-table row of sequence s. Sequences too
  // short for one window contribute none. Throws std::invalid_argument on
  // size mismatches or steps < 1.
  WindowDataset(const std::vector<LogSequence>& sequences, const std::vector<int>& state_of_sequence,
                const FeatureLayout& layout, const Normalization& norm, int steps);

  int steps() const { return steps_; }
  int size() const { return static_cast<int>(windows_.size()); }
  const Window& window(int id) const { return windows_[static_cast<std::size_t>(id)]; }
  int x_dim() const { return x_dim_; }
  int u_dim() const { return u_dim_; }
  int y_dim() const { return y_dim_; }

  // Fills `batch` (x0, u, state) and `y_target` (dims.y x N*B, step-major)
  // with the windows `ids`, in that order.
  void gather(std::span<const int> ids, WindowBatch<float>& batch, Matrix<float>& y_target) const;

  // Splits the windows of each sequence at a time index: the last `fraction`
  // of its windows go to `held_out`; `train` keeps only windows whose span
  // (rows i-1 .. i+N) ends before the first held-out window's x row, so no
  // observation is in both. fraction 0: everything trains.
  struct Split {
    std::vector<int> train, held_out;
  };
  Split split_tail(double fraction) const;

 private:
  int steps_, x_dim_, u_dim_, y_dim_;
  std::vector<Matrix<float>> x_, u_, y_;  // per sequence, standardised, one column per step
  std::vector<int> state_;
  std::vector<Window> windows_;  // sequence-major, start ascending
};

}  // namespace hadynet::trainer
