#include "trainer/output_clip.h"

#include <algorithm>
#include <stdexcept>

namespace hadynet::trainer {

namespace {

Eigen::Index row_of(const HadynetModel& model, const OutputClip& c) {
  const auto& names = model.layout.y_names;
  const auto it = std::find(names.begin(), names.end(), c.channel);
  if (it == names.end()) throw std::invalid_argument("output clip on '" + c.channel + "', not a y channel");
  return static_cast<Eigen::Index>(it - names.begin());
}

}  // namespace

void apply_output_clips(const HadynetModel& model, Eigen::MatrixXd& y) {
  for (const OutputClip& c : model.sensor.clips) {
    const std::optional<double> rail = frame_rail(model.sensor, c);
    if (!rail) continue;
    const Eigen::Index r = row_of(model, c);
    y.row(r) = c.side > 0 ? y.row(r).cwiseMin(*rail).eval() : y.row(r).cwiseMax(*rail).eval();
  }
}

std::vector<StandardisedClip> standardised_clips(const HadynetModel& model) {
  std::vector<StandardisedClip> out;
  for (const OutputClip& c : model.sensor.clips) {
    const std::optional<double> rail = frame_rail(model.sensor, c);
    if (!rail) continue;
    const Eigen::Index r = row_of(model, c);
    out.push_back({r, c.side, static_cast<float>((*rail - model.norm.y.mean(r)) / model.norm.y.std(r))});
  }
  return out;
}

long clip_standardised(const HadynetModel& model, Matrix<float>& y_hat, Matrix<float>* d_y_hat) {
  long clipped = 0;
  for (const StandardisedClip& c : standardised_clips(model)) {
    for (Eigen::Index j = 0; j < y_hat.cols(); ++j) {
      float& v = y_hat(c.row, j);
      if (c.side > 0 ? v <= c.rail : v >= c.rail) continue;
      v = c.rail;
      if (d_y_hat != nullptr) (*d_y_hat)(c.row, j) = 0.0f;
      ++clipped;
    }
  }
  return clipped;
}

}  // namespace hadynet::trainer
