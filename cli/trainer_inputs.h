// Shared input handling of the trainer subcommands (train, adapt, recognize,
// calibrate-detect, simulate): loading logs for a model's channels, grouping
// them by dynamics state, and choosing a PB from the command line.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/log_dataset.h"
#include "trainer/model_frame.h"

namespace hadynet::cli {

// Reads every log under `args` (files or folders) for the layout's channels,
// as they are (training data). Throws (LogError / std::runtime_error) naming
// the file on any problem.
std::vector<trainer::LogSequence> read_sequences(const std::vector<std::string>& args,
                                                 const trainer::FeatureLayout& layout);

// The same for a trained model: each log read in the model's own frame
// (trainer::in_model_frame; a model fixed by `hadynet residual --fix` may
// predict e.g. the channels without cross-talk).
std::vector<trainer::LogSequence> read_sequences(const std::vector<std::string>& args,
                                                 const trainer::HadynetModel& model);

// Sequences grouped by state id, groups in first-appearance order.
struct StateGroup {
  std::string state;
  std::string object;
  std::vector<trainer::LogSequence> sequences;
};
std::vector<StateGroup> group_by_state(std::vector<trainer::LogSequence> sequences);

// A PB chosen on the command line: "zero", a state name of the model's PB
// table, or comma-separated numbers. Throws std::runtime_error with a message.
Eigen::VectorXf parse_pb(const trainer::HadynetModel& model, const std::string& text);

// The start PBs of an adaptation (--start): "objects" is the zero PB and
// each object's mean trained PB (the best fit of them wins:
// trainer::adapt_pb_best_of); anything else one PB as parse_pb reads it.
std::vector<Eigen::VectorXf> parse_start_pbs(const trainer::HadynetModel& model, const std::string& text);

std::string format_pb(const Eigen::VectorXf& pb);

}  // namespace hadynet::cli
