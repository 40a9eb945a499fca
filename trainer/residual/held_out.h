// The before/after of `hadynet residual --fix` (docs/residual.md): a model's
// causal 1-step error on held-out rows of measured logs, per channel. Each
// model is fed the logs in its own frame and its predictions are read as
// measured rows through its sensor model (SensorReadout,
// sensor_readout.h): with D its largest delay, the measured row t is
// predicted from frame row t - D - 1 (known at t - 1), running D + 1 steps
// with the logged commands; every frame row the readout asks for (channel
// c's t - delay_c, a cross-talk source's t - delay_s) is the step of that
// run that predicts it. Without a sensor model this is the analysis's
// 1-step prediction.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/residual/residuals.h"
#include "trainer/residual/whiteness.h"

namespace hadynet::trainer::residual {

// Error of one model on the held-out rows, per channel (physical units).
struct HeldOutError {
  std::vector<std::string> channels;  // the model's y channels
  Eigen::VectorXd rmse;               // sqrt(mean (y - y_hat)^2)
  Eigen::VectorXd fit;                // 100 (1 - ||y - y_hat|| / ||y - mean(y)||), percent
  std::vector<Whiteness> whiteness;   // Ljung-Box etc. of the held-out 1-step residual, per channel
  std::vector<int> inputs_outside;    // lags -L..L outside the 99 % bound, summed over the inputs
  long samples = 0;                   // held-out rows (all logs)
  std::vector<Segments> residuals;    // [c]: y - y_hat of channel c on the held-out rows, one segment per log
  std::string verdict;                // attribution on the model's own frame (empty: not run)
};

// One log for held_out_error: the measured log, it in the model's layout
// (measured) and in the model's frame (frame: to_model_frame), the PB, and
// the held-out rows [first, end) of the measured log.
struct HeldOutLog {
  const LogInput* raw = nullptr;
  LogSequence measured;
  LogSequence frame;
  Eigen::VectorXf pb;
  int first = 0, end = 0;
};

// What held_out_error computes besides RMSE, fit and the residuals: the
// whiteness and independence diagnostics, which a report shows, or nothing
// more (the probes and tests that only compare errors; these diagnostics
// were about a seventh of a `--fix` run's time).
enum class HeldOutDetail { kWithDiagnostics, kErrorsOnly };

// RMSE, fit and residuals, and (kWithDiagnostics) whiteness and independence
// (against the logged commands) per channel over the held-out rows of every
// log (verdict left empty; with kErrorsOnly, whiteness and inputs_outside
// are left empty). Throws std::logic_error if a held-out row has no
// prediction (rows before D + 2).
HeldOutError held_out_error(const HadynetModel& model, const std::vector<HeldOutLog>& logs,
                            HeldOutDetail detail = HeldOutDetail::kWithDiagnostics);

// A model's RMSE per y channel (physical units, in the measured frame) over
// windows of `steps` steps: the rows [first, end) of each log are cut into
// consecutive windows, each run open loop from its initial state (the
// measured frame row before it) with the logged commands, so every row is
// predicted once, at a horizon of 1..steps. With `steps` the model's
// N_train (HadynetModel::train_steps) this is the loss it was trained on,
// in the measured frame. The predictions are read as measured rows as
// held_out_error reads them (SensorReadout), each frame row the readout asks
// for from the window that predicts it. A channel's row whose frame rows
// fall outside every window (the first delay_c rows, the last rows short of
// a window) is left out. Throws std::logic_error if `steps` < 1 or a channel
// has no row.
Eigen::VectorXd window_rmse(const HadynetModel& model, const std::vector<HeldOutLog>& logs, int steps);

}  // namespace hadynet::trainer::residual
