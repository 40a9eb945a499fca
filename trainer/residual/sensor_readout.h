// How a model's predictions in its own frame read as one log's measured
// rows: the sensor model of sensor_model.h in the direction the sensors
// report, the inverse of to_model_frame(). The before/after of
// `hadynet residual --fix` (held_out_error) and the curve's criterion
// (window_rmse) both read their predictions through it, so the two agree.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "trainer/sensor_model.h"
#include "trainer/residual/residuals.h"

namespace hadynet::trainer::residual {

class SensorReadout {
 public:
  // The sensor model `sensor` of a model with y channels `y_names`, on the
  // measured log `log` (its drifts' drivers and period). Throws
  // std::logic_error if a channel of `sensor` is not one of `y_names`, and
  // std::runtime_error naming the log's file for a bad dt_s or a missing
  // drift column.
  SensorReadout(const std::vector<std::string>& y_names, const SensorModel& sensor, const LogInput& log);

  int max_delay() const { return max_delay_; }
  int delay(Eigen::Index c) const { return delay_[static_cast<std::size_t>(c)]; }

  // Measured row t (every y channel, physical units) from `frame`, where
  // frame(c, r) is a prediction of channel c at frame row r (physical, the
  // model's frame; NaN where there is none), as to_model_frame() inverts it:
  //   channel c reads frame(c, t - delay_c) through its curve;
  //   a cross-talk adds gain frame(s, t - delay_s): the source as measured
  //     at row t, read in the frame (crosstalk_removed() subtracts the
  //     measured source of the target's row, through its curve);
  //   a drift adds rate (D(t - 1) + its step): the driver known from the
  //     measured rows up to t - 1, and the step from this row's reading
  //     (the level's magnitude times dt for a load drift, dt for time);
  //   a rail clips the reading (the network's own output is clipped at the
  //   frame's rail already, output_clip.h; a cross-talk or a drift may
  //   carry the reading past the rail, as the firmware reports it).
  // A channel is NaN where a value it reads is. Requires t >= 1.
  template <class Frame>
  Eigen::VectorXd row(const Frame& frame, int t) const {
    const auto ny = static_cast<Eigen::Index>(delay_.size());
    Eigen::VectorXd v(ny);
    for (Eigen::Index c = 0; c < ny; ++c) v(c) = frame(c, t - delay(c));
    for (const auto& [c, curve] : curves_) v(c) = curve_reading(curve, v(c));
    for (const Crosstalk& x : crosstalk_) v(x.target) += x.gain * frame(x.source, t - delay(x.source));
    for (const Drift& drift : drifts_) {
      const double known = drift.rate * drift.driver[static_cast<std::size_t>(t - 1)];
      const double step = drift.load ? std::abs(v(drift.channel)) * dt_ : dt_;
      v(drift.channel) += known + drift.rate * step;
    }
    for (const auto& [c, clip] : clips_)
      if (clip.side > 0 ? v(c) > clip.rail : v(c) < clip.rail) v(c) = clip.rail;
    return v;
  }

 private:
  struct Crosstalk {
    Eigen::Index target, source;
    double gain;
  };
  struct Drift {
    Eigen::Index channel;
    bool load;
    double rate;
    std::vector<double> driver;  // D_c of every measured row (drift_driver)
  };
  std::vector<int> delay_;  // per y channel: reported this many rows late
  int max_delay_ = 0;
  double dt_ = 1;  // the log's period (s)
  std::vector<std::pair<Eigen::Index, SensorCurve>> curves_;
  std::vector<Crosstalk> crosstalk_;
  std::vector<Drift> drifts_;
  std::vector<std::pair<Eigen::Index, OutputClip>> clips_;
};

}  // namespace hadynet::trainer::residual
