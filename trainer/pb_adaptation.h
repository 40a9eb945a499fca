// PB-only adaptation (docs/method.md, "PB adaptation"; seed paper section III-C): the
// weights stay frozen, one PB vector is fitted to data of the current
// dynamics state by MomentumSGD on the full batch (BN in eval mode).
//
// Step-size safeguard: the paper's rate (1.0) was chosen on the hand, and on
// data of another scale it diverges (the Cascaded Tanks, as issue 12
// reported for its model: 1.89 V free-run RMSE with an adapted PB against
// 0.48 V with the trained one). A step is
// kept when the full-batch loss after it is at most the largest of the last
// kSafeguardWindow losses (a non-monotone test in the style of Grippo,
// Lampariello and Lucidi 1986: momentum's bounded overshoots pass, growth
// does not); otherwise it is undone, the momentum cleared and the rate
// halved, for the rest of the call (at most kMaxHalvings times; then the PB
// stays where it was). Where the rate suits the data nothing changes.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <span>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/optim.h"
#include "trainer/window_dataset.h"

namespace hadynet::trainer {

inline constexpr int kSafeguardWindow = 10;  // losses the step test looks back over (~ 1 / (1 - momentum))
inline constexpr int kMaxHalvings = 30;      // 2^-30 of the rate: below float resolution of any PB step

// A fit of at most this many windows (every fit in the suite and the
// benchmarks) runs in one pass, as before passes were bounded; at 10 steps
// and 64 units a pass takes about 0.6 GB.
inline constexpr int kDefaultWindowsPerPass = 8192;

struct AdaptOptions {
  int epochs = 20;        // paper: N_epoch^update = 20 (online: 3)
  double lr = 1.0;        // MomentumSGD step; see docs/trainer.md for how it was chosen
  double momentum = 0.9;  // MomentumSGD momentum (Chainer's default)
  // Windows per forward/backward pass: the activations grow with windows x
  // steps, so a fit over more windows sums the losses and PB gradients of
  // chunks of this many (the same full-batch step, up to float rounding),
  // and its memory does not grow with the logs' length.
  int windows_per_pass = kDefaultWindowsPerPass;
};

struct AdaptResult {
  Eigen::VectorXf pb;
  std::vector<double> loss;  // loss[0]: with the start PB; loss[e]: after epoch e
  int halvings = 0;          // times the safeguard halved the learning rate (0: the given rate throughout)
};

// Fits one PB to the windows `ids` of `data`, starting from `start`
// (dims.pb values). Throws std::invalid_argument on size errors or no windows.
AdaptResult adapt_pb(const HadynetModel& model, const WindowDataset& data, std::span<const int> ids,
                     const Eigen::VectorXf& start, const AdaptOptions& options);

// Adapts from each of `starts` (at least one) and keeps the fit whose final
// loss is lowest (the first on ties). The PB loss has local minima: a start
// inside the right object's cluster of trained PBs can end elsewhere than a
// start at zero. Cost: one adaptation per start.
AdaptResult adapt_pb_best_of(const HadynetModel& model, const WindowDataset& data, std::span<const int> ids,
                             const std::vector<Eigen::VectorXf>& starts, const AdaptOptions& options);

// Online PB update over a stream of steps (paper: start once 100 windows are
// available, keep the newest 200, 3 full-batch epochs per new step). The
// stream may consist of several segments (e.g. one log per grasped object):
// windows never span a segment boundary, but the window buffer, the PB and
// the momentum buffer carry over, as they would on the robot.
class OnlinePbAdapter {
 public:
  struct Options {
    int start_windows = 100;  // N_thre^online
    int max_windows = 200;    // N_max^online
    AdaptOptions adapt{3, 1.0, 0.9};
  };

  // `model` is referenced, not copied: it must outlive the adapter.
  OnlinePbAdapter(const HadynetModel& model, Eigen::VectorXf start, Options options);

  // Appends the next step (physical units: observed y_t, command u_t) of the
  // current segment. A window {x_i, u_[i,i+N), y_[i+1,i+N]} is complete once
  // y_{i+N} has arrived (and i >= 1 within the segment). Returns true if the
  // PB was updated at this step (enough windows, and a new one arrived).
  bool push(const Eigen::VectorXd& y, const Eigen::VectorXd& u);
  // Starts a new segment: the next push is step 0 of a new recording.
  void begin_segment();

  const Eigen::VectorXf& pb() const { return pb_; }
  int windows() const { return static_cast<int>(x_.size()); }  // <= max_windows
  double last_loss() const { return last_loss_; }  // after the last update; NaN before

 private:
  const HadynetModel& model_;
  Options options_;
  Eigen::VectorXf pb_;
  HadynetParams<float> params_;  // model weights with a one-row PB table
  MomentumSgd<float> sgd_;
  std::deque<Eigen::VectorXd> rows_y_, rows_u_;  // last N+1 rows of the current segment
  long segment_steps_ = 0;                       // steps pushed in the current segment
  std::deque<Eigen::VectorXf> x_;                // standardised windows, oldest first
  std::deque<Matrix<float>> u_, y_;              // u x N and y x N per window
  double last_loss_;
};

}  // namespace hadynet::trainer
