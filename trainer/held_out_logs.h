// The held-out rows of the training logs, kept in the model file as logs
// (HadynetModel::held_out_logs): the clean data the residual loop calibrates
// its null on when no other reference logs are given (docs/residual.md,
// "A calibrated null").
#pragma once

#include <string>
#include <vector>

#include "datalog/log_table.h"
#include "trainer/hadynet_model.h"
#include "trainer/window_dataset.h"

namespace hadynet::trainer {

// For each training log with held-out windows (`split` of `data`, whose
// sequence s was read from paths[s]): its rows from the first held-out
// window's x row - 1 (the delta rows need it) to its end, with the log's
// metadata and header, as a StoredLog named "PATH rows A..B" (0-based data
// rows). No training window touches these rows (WindowDataset::split_tail).
// Re-reads each log (one in memory at a time). Empty when nothing is held out.
std::vector<StoredLog> held_out_logs(const std::vector<std::string>& paths, const WindowDataset& data,
                                     const WindowDataset::Split& split);

// True when `log` holds every row of `part` (same column names; every value
// equal), consecutively: `part` was cut from it, so `part` is not other data
// than `log`.
bool contains_rows(const datalog::LogTable& log, const datalog::LogTable& part);

}  // namespace hadynet::trainer
