// A sensor's rated range (its datasheet): a measured channel cannot leave
// it, so neither may the model's prediction. `hadynet residual --rated-range`
// gives the ranges a user knows; they are applied as known output clips
// (sensor_model.h) before anything is searched, so the library's saturation
// rails look only for clipping the datasheet does not explain. A clip the
// model already has on a side (e.g. from an earlier --fix) is kept.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "trainer/hadynet_model.h"

namespace hadynet::trainer::residual {

struct RatedRange {
  std::string name;           // a y group prefix ("fc": fc0, fc1, ...) or one y channel ("fc3")
  std::optional<double> low;  // physical units; absent: no lower limit
  std::optional<double> high;
};

// "fc=0..50", "y0=..10", "f=0..": NAME=[LOW]..[HIGH], at least one bound,
// LOW < HIGH. Throws std::invalid_argument naming the fault.
RatedRange parse_rated_range(const std::string& text);

// The range of output channel `channel` in `ranges`: its own (NAME the
// channel) wins over its group's; none when neither is given.
const RatedRange* rated_range_of(const std::vector<RatedRange>& ranges, const std::string& channel);

// `model` with a clip at each given bound of each channel a range names (a
// channel's own range wins over its group's), except where the model already
// clips that side. `added` (optional) receives the clips added. Throws
// std::invalid_argument when a name matches no y channel of the model.
HadynetModel with_rated_ranges(const HadynetModel& model, const std::vector<RatedRange>& ranges,
                               std::vector<OutputClip>* added = nullptr);

}  // namespace hadynet::trainer::residual
