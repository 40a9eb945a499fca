// A measured log read in a model's own frame (sensor_model.h): the one way
// the trainer side feeds a model logs. A model fixed by `hadynet residual
// --fix` predicts e.g. a channel without its cross-talk, aligned in time or
// without its drift; every reader of logs for a model (the trainer commands'
// read_sequences, the residual analysis, --fix's training data and its
// before/after evaluation) moves the log into that frame here first.
#pragma once

#include <string>

#include "datalog/log_table.h"
#include "trainer/log_dataset.h"
#include "trainer/sensor_model.h"

namespace hadynet::trainer {

struct ModelFrameLog {
  // The log in the frame (to_model_frame: drift and cross-talk removed, the
  // delayed channels aligned and the rows a delay costs dropped); the
  // measured log as it is when the frame is the measured one.
  datalog::LogTable table;
  LogSequence sequence;  // the layout's channels of `table` (log_sequence)
};

// `measured` (a log as recorded; `file` names it in messages) in the frame of
// a model with sensor model `sensor` and channel layout `layout` (for a
// model: its `sensor` and `layout`). Throws std::runtime_error naming `file`
// for a missing column, a bad dt_s or a log shorter than a delay.
ModelFrameLog in_model_frame(const SensorModel& sensor, const FeatureLayout& layout,
                             const datalog::LogTable& measured, const std::string& file);

}  // namespace hadynet::trainer
