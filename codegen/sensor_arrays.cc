#include "codegen/sensor_arrays.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>

#include "codegen/formats.h"
#include "codegen/header_text.h"
#include "codegen/unsupported_model.h"
#include "trainer/derived_inputs.h"

namespace hadynet::codegen {

SensorArrays sensor_arrays(const trainer::HadynetModel& model, bool q15, int frac_y) {
  const auto& y = model.layout.y_names;
  const auto& u = model.layout.u_names;
  const auto y_index = [&](const std::string& name) -> Eigen::Index {
    const auto it = std::find(y.begin(), y.end(), name);
    if (it == y.end()) reject("sensor model names '" + name + "', not a y channel");
    return it - y.begin();
  };
  SensorArrays a;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const auto d = trainer::parse_derived_input(u[i]);
    if (!d) {
      a.derived.push_back("hadynet::firmware::DerivedKind::kNone");
      a.derived_base.push_back(std::to_string(i));
      a.derived_lag.push_back("0");
      continue;
    }
    const auto it = std::find(u.begin(), u.end(), d->base);
    if (it == u.end()) reject("derived input '" + u[i] + "': no command '" + d->base + "' in the model");
    if (trainer::parse_derived_input(d->base)) reject("derived input '" + u[i] + "' is derived from a derived input");
    switch (d->kind) {
      case trainer::DerivedKind::kSign: a.derived.push_back("hadynet::firmware::DerivedKind::kSign"); break;
      case trainer::DerivedKind::kHysteresis: a.derived.push_back("hadynet::firmware::DerivedKind::kHysteresis"); break;
      case trainer::DerivedKind::kChangeSign: a.derived.push_back("hadynet::firmware::DerivedKind::kChangeSign"); break;
      case trainer::DerivedKind::kChangeHysteresis:
        a.derived.push_back("hadynet::firmware::DerivedKind::kChangeHysteresis");
        break;
      case trainer::DerivedKind::kLag: a.derived.push_back("hadynet::firmware::DerivedKind::kLag"); break;
    }
    a.derived_base.push_back(std::to_string(it - u.begin()));
    a.derived_lag.push_back(std::to_string(d->lag));
  }
  const trainer::SensorModel& s = model.sensor;
  for (const auto& x : s.crosstalk) {
    a.crosstalk_target.push_back(std::to_string(y_index(x.target)));
    a.crosstalk_source.push_back(std::to_string(y_index(x.source)));
    a.crosstalk_gain.push_back(float_literal(static_cast<float>(x.gain)));
  }
  for (const auto& d : s.drifts) {
    a.drift_channel.push_back(std::to_string(y_index(d.channel)));
    a.drift_is_load.push_back(d.load ? "true" : "false");
    a.drift_rate.push_back(float_literal(static_cast<float>(d.rate)));
  }
  if (!s.drifts.empty()) a.period = float_literal(static_cast<float>(s.period_s));
  for (const auto& c : s.clips) {
    const Eigen::Index r = y_index(c.channel);
    a.clip_channel.push_back(std::to_string(r));
    a.clip_side.push_back(std::to_string(c.side));
    a.clip_rail.push_back(float_literal(static_cast<float>(c.rail)));
    // The rail on the network's channel (trainer/sensor_model.h); none (a cross-talk
    // target, a drifting channel): the type's extreme on the clip's side,
    // which never clips.
    const std::optional<double> rail = trainer::frame_rail(s, c);
    if (!rail) {
      const float extreme = c.side > 0 ? std::numeric_limits<float>::max() : std::numeric_limits<float>::lowest();
      a.clip_rail_model.push_back(q15 ? (c.side > 0 ? "32767" : "-32768") : float_literal(extreme));
      continue;
    }
    const double standardised = (*rail - model.norm.y.mean(r)) / model.norm.y.std(r);
    a.clip_rail_model.push_back(
        q15 ? std::to_string(std::clamp<std::int64_t>(to_fixed(standardised, frac_y), -32768, 32767))
            : float_literal(static_cast<float>(standardised)));
  }
  // The firmware's curves share one knot count (a compile-time size): the
  // largest. A curve with fewer knots gets more beyond its top knot, on its
  // last segment's extension, where g continues anyway (sensor_model.h), so
  // g is unchanged.
  std::size_t knots = 0;
  for (const auto& c : s.curves) knots = std::max(knots, c.level.size());
  for (const auto& c : s.curves) {
    a.curve_channel.push_back(std::to_string(y_index(c.channel)));
    std::vector<double> level = c.level, reading = c.reading;
    for (std::size_t n = c.level.size(); level.size() < knots;) {
      const auto step = static_cast<double>(level.size() + 1 - n);  // 1, 2, ... segments beyond the top knot
      level.push_back(c.level[n - 1] + step * (c.level[n - 1] - c.level[n - 2]));
      reading.push_back(c.reading[n - 1] + step * (c.reading[n - 1] - c.reading[n - 2]));
    }
    for (std::size_t k = 0; k < level.size(); ++k) {
      const float l = static_cast<float>(level[k]), r = static_cast<float>(reading[k]);
      // The firmware divides by the knots' differences in float.
      if (k > 0 && !(l > static_cast<float>(level[k - 1]) && r > static_cast<float>(reading[k - 1])))
        reject("sensor curve of " + c.channel + ": knots " + std::to_string(k - 1) + " and " + std::to_string(k) +
               " are equal in float (the firmware's curves are float)");
      a.curve_level.push_back(float_literal(l));
      a.curve_reading.push_back(float_literal(r));
    }
  }
  if (!s.curves.empty()) a.curve_knots = static_cast<int>(knots);
  a.curve_count = static_cast<int>(a.curve_channel.size());
  if (a.curve_channel.empty()) {
    a.curve_channel = {"0"};
    a.curve_level = a.curve_reading = {"0.0f", "1.0f"};
  }
  a.crosstalk_count = static_cast<int>(a.crosstalk_target.size());
  a.drift_count = static_cast<int>(a.drift_channel.size());
  a.clip_count = static_cast<int>(a.clip_channel.size());
  for (auto* v : {&a.crosstalk_target, &a.crosstalk_source, &a.drift_channel, &a.clip_channel, &a.clip_side})
    if (v->empty()) v->push_back("0");
  for (auto* v : {&a.crosstalk_gain, &a.drift_rate, &a.clip_rail})
    if (v->empty()) v->push_back("0.0f");
  if (a.drift_is_load.empty()) a.drift_is_load.push_back("false");
  if (a.clip_rail_model.empty()) a.clip_rail_model.push_back(q15 ? "0" : "0.0f");
  for (const std::string& l : s.describe()) a.notes.push_back(l);
  for (const auto& d : s.delays)
    a.notes.push_back(d.channel + ": the firmware does not undo this delay (it needs future samples); the " +
                      "network sees the late measurement");
  return a;
}

}  // namespace hadynet::codegen
