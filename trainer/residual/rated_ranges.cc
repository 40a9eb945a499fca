#include "trainer/residual/rated_ranges.h"

#include <algorithm>
#include <stdexcept>

#include "datalog/log_rules.h"
#include "trainer/log_dataset.h"

namespace hadynet::trainer::residual {

namespace {

std::optional<double> parse_bound(const std::string& text, const std::string& whole) {
  if (text.empty()) return std::nullopt;
  const std::optional<double> v = datalog::rules::parse_finite_number(text);
  if (!v) throw std::invalid_argument("rated range '" + whole + "': '" + text + "' is not a number");
  return v;
}

}  // namespace

RatedRange parse_rated_range(const std::string& text) {
  const auto eq = text.find('=');
  const auto dots = text.find("..", eq == std::string::npos ? 0 : eq);
  if (eq == std::string::npos || eq == 0 || dots == std::string::npos)
    throw std::invalid_argument("rated range '" + text + "': expected NAME=LOW..HIGH (e.g. fc=0..50)");
  RatedRange r;
  r.name = text.substr(0, eq);
  r.low = parse_bound(text.substr(eq + 1, dots - eq - 1), text);
  r.high = parse_bound(text.substr(dots + 2), text);
  if (!r.low && !r.high) throw std::invalid_argument("rated range '" + text + "': give LOW, HIGH or both");
  if (r.low && r.high && !(*r.low < *r.high))
    throw std::invalid_argument("rated range '" + text + "': LOW must be below HIGH");
  return r;
}

const RatedRange* rated_range_of(const std::vector<RatedRange>& ranges, const std::string& channel) {
  const RatedRange* range = nullptr;
  for (const RatedRange& r : ranges) {
    if (r.name == channel) range = &r;
    else if (!range && r.name == channel_group(channel)) range = &r;
  }
  return range;
}

HadynetModel with_rated_ranges(const HadynetModel& model, const std::vector<RatedRange>& ranges,
                               std::vector<OutputClip>* added) {
  HadynetModel out = model;
  const auto& names = model.layout.y_names;
  for (const RatedRange& r : ranges) {
    const bool any = std::any_of(names.begin(), names.end(),
                                 [&](const std::string& c) { return c == r.name || channel_group(c) == r.name; });
    if (!any) throw std::invalid_argument("rated range '" + r.name + "': no output channel or group of that name");
  }
  for (const std::string& channel : names) {
    const RatedRange* range = rated_range_of(ranges, channel);
    if (!range) continue;
    for (const int side : {-1, +1}) {
      const std::optional<double>& bound = side < 0 ? range->low : range->high;
      if (!bound) continue;
      const bool clipped = std::any_of(out.sensor.clips.begin(), out.sensor.clips.end(), [&](const OutputClip& c) {
        return c.channel == channel && c.side == side;
      });
      if (clipped) continue;
      out.sensor.clips.push_back({channel, side, *bound});
      if (added) added->push_back(out.sensor.clips.back());
    }
  }
  return out;
}

}  // namespace hadynet::trainer::residual
