// Preparing a trained model for codegen (issue 4): the value ranges of every
// tensor the firmware computes, from which codegen picks per-tensor
// fixed-point formats (the batch norm fold is in batch_norm_fold.h).
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "trainer/batch_norm_fold.h"
#include "trainer/hadynet_model.h"
#include "trainer/window_dataset.h"

namespace hadynet::trainer {


// Largest absolute value of each quantity the firmware's forward computes,
// over the windows `ids` of `data` with their states' PBs (BN eval), in
// standardised units (ValueRanges, trainer/hadynet_model.h). Weights' ranges
// are read from the parameters. Sets `windows` to ids.size(); `source` is
// left for the caller.
ValueRanges measure_ranges(const HadynetModel& model, const WindowDataset& data,
                           std::span<const int> ids);

// measure_ranges over every window (N_train steps) of the logs under
// `log_args` (files or folders, see expand_log_paths). Each log's state
// (metadata "state") must be a row of the model's PB table; its windows run
// with that PB. `source` names the logs and their content hash. Throws
// std::runtime_error naming the file (unreadable log, other channels, a state
// not in the PB table) or when the logs hold no window.
ValueRanges measure_log_ranges(const HadynetModel& model, const std::vector<std::string>& log_args);

}  // namespace hadynet::trainer
