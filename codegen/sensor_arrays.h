// The derived-input and sensor-model arrays of a generated header
// (firmware/core/model_contract.h, "derived inputs" and "sensor model"), as
// literals; every array holds max(count, 1) entries (a zero entry when
// empty, since C++ has no zero-length arrays).
#pragma once

#include <string>
#include <vector>

#include "trainer/hadynet_model.h"

namespace hadynet::codegen {

struct SensorArrays {
  std::vector<std::string> derived, derived_base, derived_lag;
  int crosstalk_count = 0, drift_count = 0, clip_count = 0, curve_count = 0;
  int curve_knots = 2;  // knots of every curve: the most of any (others padded on their end segment); 2 without
  // Knot k of curve j at [j * curve_knots + k]; without a curve one identity
  // segment (0 -> 0, 1 -> 1) that is never used.
  std::vector<std::string> curve_channel, curve_level, curve_reading;
  std::vector<std::string> crosstalk_target, crosstalk_source, crosstalk_gain;
  std::vector<std::string> drift_channel, drift_is_load, drift_rate;
  std::string period = "0.0f";
  std::vector<std::string> clip_channel, clip_side, clip_rail, clip_rail_model;
  std::vector<std::string> notes;  // comment lines
};

// The arrays of `model` (q15: clip rails in Q(frac_y)). Throws
// UnsupportedModel when the sensor model or a derived input names a channel
// the model does not have, or when a curve's knots are not strictly
// increasing once rounded to float.
SensorArrays sensor_arrays(const trainer::HadynetModel& model, bool q15, int frac_y);

}  // namespace hadynet::codegen
