// What a model knows about its sensors beyond the network: how the measured
// channels follow from the channels the network predicts (its "frame").
// Added by `hadynet residual --fix` (docs/residual.md); empty for a model
// trained on logs as they are. With the network's channels y' (physical
// units, the model's frame), a measured channel is
//
//   y_c(t) = clip_c( g_c(y'_c(t - delay_c)) + sum_s k_cs y'_s(t - delay_s) + b_c(t) )
//
//   delay_c y_c is reported `steps` rows late (a sensor delay);
//   g_c     a static calibration curve: the sensor reports a monotone
//           function of its channel's level (identity without one);
//   k_cs    cross-talk: the target picks up `gain` times the source as
//           measured in the same row (so its own delay applies);
//   b_c     a drift/bias state, rate * D_c(t), D_c the load the sensor has
//           carried since the log's start (its level, the reading less the
//           bias, accumulated: SensorDrift) or the time since then (t dt),
//           from the measured column;
//   clip_c  a rail the sensor saturates at (side +1: min(., rail); -1: max).
//
// to_model_frame() moves a log into the model's frame (the inverse: the
// delay undone, which is not causal, cross-talk and drift removed, the
// curve inverted); every prediction is clipped at each clip's frame rail
// (frame_rail below, output_clip.h) and, as measured, at its rail. Whoever feeds the
// network logs or frames must apply it: the trainer's commands do
// (read_sequences), the firmware applies cross-talk, drift, curves and clips
// at its boundary (docs/firmware.md).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "datalog/log_table.h"

namespace hadynet::trainer {

struct SensorDelay {
  std::string channel;  // a y channel reported late
  int steps = 0;        // rows, >= 1

  bool operator==(const SensorDelay&) const = default;
};

struct SensorCrosstalk {
  std::string target, source;  // y channels
  double gain = 0;             // target units per source unit

  bool operator==(const SensorCrosstalk&) const = default;
};

// A sensor bias b = rate D growing with a driver D (SensorModel):
//   load: D is the channel's accumulated level in the model frame, the
//     reading y less its bias, over time: D_r = D_r-1 + dt (|y_r| - b_r),
//     solved as D_r = (D_r-1 + dt |y_r|) / (1 + rate dt) (the level's
//     magnitude where the level is >= 0, a loadcell's force). A bias that
//     grows with the true load (creep) is driven by the level, not by the
//     reading: a driver of the reading (before stop 54) counts the bias
//     itself and, at 0.02 per N s, read the plant's bias 1.4-1.7 times too
//     high by the end of a 60 s log (docs/residual-experiments.md, "The plant's own
//     effect as the fix"). Its rate is >= 0 (check()): with a negative
//     rate 1 / (1 + rate dt) > 1 and D grows exponentially;
//   time: D_r = r dt.
struct SensorDrift {
  std::string channel;  // a y channel
  bool load = true;     // D = accumulated level; false: time
  double rate = 0;      // channel units per (channel unit s), or per s

  bool operator==(const SensorDrift&) const = default;
};

// A static calibration curve g: the sensor reads g(level) when its
// channel's level (the model's frame, physical units) is `level`. g is
// piecewise linear through the knots (level[i], reading[i]), both strictly
// increasing (so g is monotone and invertible), and continues beyond the end
// knots along the end segments.
struct SensorCurve {
  std::string channel;          // a y channel
  std::vector<double> level;    // >= 2 knots, strictly increasing (channel units, the model's frame)
  std::vector<double> reading;  // the reading at each knot, strictly increasing (channel units, measured)

  bool operator==(const SensorCurve&) const = default;
};
// g(level) and its inverse g^-1(reading) (curve_level(c, curve_reading(c, v))
// == v up to rounding).
double curve_reading(const SensorCurve& curve, double level);
double curve_level(const SensorCurve& curve, double reading);
// g'(level): the slope (reading per level) of the segment holding `level`
// (at a knot, the segment above it; beyond the end knots, the end segment).
double curve_slope(const SensorCurve& curve, double level);

struct OutputClip {
  std::string channel;  // a y channel
  int side = 1;         // +1 upper rail, -1 lower rail
  double rail = 0;      // physical units

  bool operator==(const OutputClip&) const = default;
};

struct SensorModel {
  std::vector<SensorDelay> delays;  // one per delayed channel
  std::vector<SensorCrosstalk> crosstalk;
  std::vector<SensorDrift> drifts;
  std::vector<SensorCurve> curves;  // at most one per channel
  std::vector<OutputClip> clips;
  // The control period (s) of the logs the drifts were fitted on: D of a
  // load drift grows by |y_c| period_s per row (the firmware integrates it).
  double period_s = 0;

  bool empty() const { return frame_is_measured() && clips.empty(); }
  // The frame transform (delay, cross-talk, drift, curves) is the identity.
  bool frame_is_measured() const {
    return delays.empty() && crosstalk.empty() && drifts.empty() && curves.empty();
  }
  // The channel's curve, nullptr without one.
  const SensorCurve* curve_of(const std::string& channel) const;
  // The largest delay (rows; 0 without one), and the delay of a channel.
  int max_delay() const;
  int delay_of(const std::string& channel) const;
  // Throws std::invalid_argument naming the first entry whose channel is not
  // in `y_names` or whose numbers are invalid.
  void check(const std::vector<std::string>& y_names) const;
  // One line per part, e.g. "fc2 += 0.252 * fc3"; empty if none.
  std::vector<std::string> describe() const;

  bool operator==(const SensorModel&) const = default;
};

// The rail of `clip` on the network's channel y'_c (physical, the model's
// frame): the rail itself for a plain or delayed channel, g_c^-1(rail) for a
// channel with a curve (g increases, so the side is kept); none for a
// cross-talk target or a drifting channel, whose measured value is y'_c plus
// a term that changes every row (the clip then bounds the measured value
// only). output_clip.h and the firmware's clip before detection
// (kClipRailModel) use it.
std::optional<double> frame_rail(const SensorModel& sensor, const OutputClip& clip);

// Whether the model's frame reads `channel` other than as measured (up to a
// delay): through a calibration curve, or with a cross-talk or a drift
// removed. A level of such a channel in the frame is not a sensor reading.
bool frame_transforms(const SensorModel& sensor, const std::string& channel);

// The control period of a log: metadata dt_s (s), 1 if absent. Throws
// std::runtime_error naming `file` if it is not a positive number.
double log_dt(const datalog::LogTable& table, const std::string& file);

// D_c of every row (see SensorDrift) from the measured column (a load
// driver with the drift's rate).
std::vector<double> drift_driver(const datalog::LogTable& table, const std::string& file, const SensorDrift& drift);

// The parts of the frame transform, each on a copy; a missing column is a
// std::runtime_error naming `file`.
//   time_aligned: each delayed channel shifted its `steps` rows earlier,
//                 y'_c(s) = y_c(s + steps); the last max_delay rows are dropped.
//   crosstalk_removed: target -= gain * source, every row (a source with a
//                 curve in `curves` read through it: the model frame's
//                 source, which the sensor model adds back).
//   drift_removed: y_c -= rate * D_c (D_c from the measured column, see
//                 SensorDrift), every row.
//   curves_inverted: y_c = g_c^-1(y_c), every row.
datalog::LogTable time_aligned(const datalog::LogTable& table, const std::string& file,
                               const std::vector<SensorDelay>& delays);
datalog::LogTable crosstalk_removed(const datalog::LogTable& table, const std::string& file,
                                    const std::vector<SensorCrosstalk>& crosstalk,
                                    const std::vector<SensorCurve>& curves = {});
datalog::LogTable drift_removed(const datalog::LogTable& table, const std::string& file,
                                const std::vector<SensorDrift>& drifts);
datalog::LogTable curves_inverted(const datalog::LogTable& table, const std::string& file,
                                  const std::vector<SensorCurve>& curves);

// A measured log in the model's frame: drift removed, then cross-talk
// removed, then the curves inverted, then time-aligned (the inverse of the
// sensor model's order).
datalog::LogTable to_model_frame(const SensorModel& sensor, const datalog::LogTable& table, const std::string& file);

}  // namespace hadynet::trainer
