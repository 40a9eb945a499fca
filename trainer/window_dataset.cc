#include "trainer/window_dataset.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hadynet::trainer {

WindowDataset::WindowDataset(const std::vector<LogSequence>& sequences,
                             const std::vector<int>& state_of_sequence, const FeatureLayout& layout,
                             const Normalization& norm, int steps)
    : steps_(steps),
      x_dim_(static_cast<int>(layout.x_names.size())),
      u_dim_(static_cast<int>(layout.u_names.size())),
      y_dim_(static_cast<int>(layout.y_names.size())),
      state_(state_of_sequence) {
  if (steps < 1) throw std::invalid_argument("windows need >= 1 step, got " + std::to_string(steps));
  if (state_of_sequence.size() != sequences.size()) {
    throw std::invalid_argument("window dataset: one state index per sequence expected");
  }
  for (std::size_t s = 0; s < sequences.size(); ++s) {
    const LogSequence& seq = sequences[s];
    const int T = seq.steps();
    Matrix<double> x = Matrix<double>::Zero(x_dim_, T);
    for (int t = 1; t < T; ++t) x.col(t) = norm.x.standardize(initial_state(layout, seq, t));
    const Matrix<double> u = (seq.u.colwise() - norm.u.mean).array().colwise() / norm.u.std.array();
    const Matrix<double> y = (seq.y.colwise() - norm.y.mean).array().colwise() / norm.y.std.array();
    x_.push_back(x.cast<float>());
    u_.push_back(u.cast<float>());
    y_.push_back(y.cast<float>());
    for (int i = 1; i + steps <= T - 1; ++i) windows_.push_back({static_cast<int>(s), i});
  }
}

void WindowDataset::gather(std::span<const int> ids, WindowBatch<float>& batch,
                           Matrix<float>& y_target) const {
  const auto B = static_cast<Eigen::Index>(ids.size());
  const Eigen::Index N = steps_;
  batch.x0.resize(x_dim_, B);
  batch.u.resize(u_dim_, N * B);
  batch.pb.resize(0, 0);
  batch.state.resize(ids.size());
  y_target.resize(y_dim_, N * B);
  for (Eigen::Index b = 0; b < B; ++b) {
    const Window& w = windows_.at(static_cast<std::size_t>(ids[static_cast<std::size_t>(b)]));
    const auto s = static_cast<std::size_t>(w.sequence);
    batch.state[static_cast<std::size_t>(b)] = state_[s];
    batch.x0.col(b) = x_[s].col(w.start);
    for (Eigen::Index k = 0; k < N; ++k) {
      batch.u.col(k * B + b) = u_[s].col(w.start + k);
      y_target.col(k * B + b) = y_[s].col(w.start + k + 1);
    }
  }
}

WindowDataset::Split WindowDataset::split_tail(double fraction) const {
  if (!(fraction >= 0.0 && fraction < 1.0)) {
    throw std::invalid_argument("held-out fraction must be in [0, 1)");
  }
  Split split;
  std::size_t begin = 0;
  while (begin < windows_.size()) {
    std::size_t end = begin;
    while (end < windows_.size() && windows_[end].sequence == windows_[begin].sequence) ++end;
    const auto n = static_cast<long>(end - begin);
    const long held = static_cast<long>(std::lround(fraction * static_cast<double>(n)));
    const long first_held = n - held;  // offset of the first held-out window
    const int first_held_x_row =
        held > 0 ? windows_[begin + static_cast<std::size_t>(first_held)].start - 1 : 1 << 30;
    for (long k = 0; k < n; ++k) {
      const auto id = static_cast<int>(begin + static_cast<std::size_t>(k));
      if (k >= first_held) {
        split.held_out.push_back(id);
      } else if (windows_[static_cast<std::size_t>(id)].start + steps_ < first_held_x_row) {
        split.train.push_back(id);
      }
    }
    begin = end;
  }
  return split;
}

}  // namespace hadynet::trainer
