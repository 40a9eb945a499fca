#include "trainer/model_frame.h"

namespace hadynet::trainer {

ModelFrameLog in_model_frame(const SensorModel& sensor, const FeatureLayout& layout,
                             const datalog::LogTable& measured, const std::string& file) {
  ModelFrameLog out;
  out.table = to_model_frame(sensor, measured, file);
  out.sequence = log_sequence(out.table, file, layout);
  return out;
}

}  // namespace hadynet::trainer
