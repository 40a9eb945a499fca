#include "trainer/normalization.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace hadynet::trainer {

namespace {

// Accumulates columns; returns mean and floored std.
class Moments {
 public:
  explicit Moments(Eigen::Index n) : sum_(Eigen::VectorXd::Zero(n)), sq_(Eigen::VectorXd::Zero(n)) {}
  void add(const Eigen::VectorXd& v) {
    // Shifted by the first sample for numerical safety (values like 250 mm).
    if (count_ == 0) shift_ = v;
    const Eigen::VectorXd d = v - shift_;
    sum_ += d;
    sq_ += d.cwiseProduct(d);
    ++count_;
  }
  ChannelScaling scaling(const std::vector<std::string>& names) const {
    const double n = static_cast<double>(count_);
    ChannelScaling s;
    const Eigen::VectorXd mean_d = sum_ / n;
    s.mean = shift_ + mean_d;
    s.std = (sq_ / n - mean_d.cwiseProduct(mean_d)).cwiseMax(0.0).cwiseSqrt();
    std::map<std::string, std::vector<double>> by_group;
    for (std::size_t i = 0; i < names.size(); ++i)
      by_group[channel_group(names[i])].push_back(s.std(static_cast<Eigen::Index>(i)));
    std::map<std::string, double> median;
    for (auto& [g, v] : by_group) {
      std::sort(v.begin(), v.end());
      median[g] = v[v.size() / 2];
    }
    for (std::size_t i = 0; i < names.size(); ++i) {
      const auto k = static_cast<Eigen::Index>(i);
      s.std(k) = std::max(s.std(k), kStdFloorOfGroupMedian * median[channel_group(names[i])]);
      if (!(s.std(k) > 1e-12)) s.std(k) = 1.0;
    }
    return s;
  }
  long count() const { return count_; }

 private:
  Eigen::VectorXd sum_, sq_, shift_;
  long count_ = 0;
};

}  // namespace

Normalization fit_normalization(const std::vector<LogSequence>& sequences,
                                const FeatureLayout& layout) {
  Moments x(static_cast<Eigen::Index>(layout.x_names.size()));
  Moments u(static_cast<Eigen::Index>(layout.u_names.size()));
  Moments y(static_cast<Eigen::Index>(layout.y_names.size()));
  for (const LogSequence& seq : sequences) {
    for (int t = 0; t < seq.steps(); ++t) {
      if (t >= 1) x.add(initial_state(layout, seq, t));
      u.add(seq.u.col(t));
      y.add(seq.y.col(t));
    }
  }
  if (x.count() == 0) {
    throw std::invalid_argument("normalisation: the logs hold no step with a predecessor");
  }
  return Normalization{x.scaling(layout.x_names), u.scaling(layout.u_names),
                       y.scaling(layout.y_names)};
}

}  // namespace hadynet::trainer
