// Offline PB adaptation shared by `adapt`, `recognize` and `calibrate-detect`:
// the command-line options and one adaptation per dynamics state.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "cli/options.h"
#include "cli/trainer_inputs.h"
#include "trainer/pb_adaptation.h"

namespace hadynet::cli {

// --start, --epochs, --lr, --momentum.
void add_adapt_options(Options& opt);
std::optional<trainer::AdaptOptions> adapt_options(const Options& opt);

struct AdaptedState {
  std::string state, object;
  int windows = 0;
  trainer::AdaptResult result;
  double drop_percent() const {
    return 100.0 * (1.0 - result.loss.back() / result.loss.front());
  }
};

// Adapts one PB per group on all its windows (N_train steps each).
// With several starts (parse_start_pbs), the best fit of them.
std::vector<AdaptedState> adapt_each_state(const trainer::HadynetModel& model,
                                           const std::vector<StateGroup>& groups,
                                           const std::vector<Eigen::VectorXf>& starts,
                                           const trainer::AdaptOptions& options);

void write_adapt_json(const std::string& path, const std::vector<AdaptedState>& results);

}  // namespace hadynet::cli
