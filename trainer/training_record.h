// What a trained model records about its own training (trainer/hadynet_model.h):
// the PB table's states, taken from the logs, and the provenance and
// hyper-parameter entries of the model file. `hadynet train` builds them
// here so that every trainer (the command, tests, benchmarks) writes the same
// schema.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/log_dataset.h"
#include "trainer/training.h"

namespace hadynet::trainer {

// One PB row per dynamics state (the logs' `state` metadata), sorted by
// name, with the state's object label; and each sequence's row.
struct PbStateTable {
  std::vector<PbState> states;
  std::vector<int> state_of_sequence;  // [i]: row of sequences[i]
};
// Throws std::runtime_error naming the log when one state has two objects.
PbStateTable pb_state_table(const std::vector<LogSequence>& sequences);

// Where the model came from. Keys: data_hash (data_hash.h: SHA-256 of the logs),
// git_commit, hadynet_version, logs (how many), created_utc (ISO 8601).
std::map<std::string, std::string> training_provenance(const std::vector<std::string>& log_paths,
                                                       const std::string& git_commit, const std::string& version);

// How it was trained. Keys: epochs, batch, steps, lr (as given: `lr_text`),
// optimizer, seed, variable_pb, held_out_fraction (as given), train_windows,
// held_out_windows, loss; `hadynet train` adds epochs_done as it goes.
struct TrainingShape {
  int steps = 0;  // window length N_train
  std::string lr_text, held_out_text;
  std::size_t train_windows = 0, held_out_windows = 0;
};
std::map<std::string, std::string> training_hyper_parameters(const TrainOptions& options, const TrainingShape& shape);

// The current UTC time as "YYYY-MM-DDThh:mm:ssZ".
std::string utc_now();

}  // namespace hadynet::trainer
