#include "trainer/residual/whiteness.h"

#include <cmath>

namespace hadynet::trainer::residual {

Segments residual_segments(const ResidualData& data, int c) {
  Segments out;
  for (const auto& log : data.logs) out.push_back(log.r.row(c).transpose());
  return out;
}

Segments input_segments(const ResidualData& data, int j) {
  Segments out;
  for (const auto& log : data.logs) out.push_back(log.seq.u.row(j).segment(ResidualLog::kFirstRow, log.size()).transpose());
  return out;
}

Segments observed_segments(const ResidualData& data, int j) {
  Segments out;
  for (const auto& log : data.logs) out.push_back(log.seq.y.row(j).segment(ResidualLog::kFirstRow, log.size()).transpose());
  return out;
}

Whiteness whiteness(const Segments& residual, int max_lag) {
  Whiteness w;
  w.acf = autocorrelation(residual, max_lag);
  w.bound = correlation_bound_99(total_samples(residual));
  w.outside = static_cast<int>((w.acf.array().abs() > w.bound).count());
  w.ljung_box = ljung_box(residual, max_lag);
  return w;
}

CrossCorrelation cross_correlate(const Segments& residual, const Segments& input, int max_lag) {
  CrossCorrelation x;
  x.rho = cross_correlation(residual, input, max_lag);
  x.bound = correlation_bound_99(total_samples(residual));
  x.outside = static_cast<int>((x.rho.array().abs() > x.bound).count());
  Eigen::Index at = 0;
  if (x.rho.size() > 0) x.rho.cwiseAbs().maxCoeff(&at);
  x.peak_lag = static_cast<int>(at) - max_lag;
  x.peak = x.rho.size() > 0 ? x.rho(at) : 0.0;
  return x;
}

}  // namespace hadynet::trainer::residual
