// The residual tests on the 1-step residuals (docs/residual.md), computed per
// log and pooled (statistics.h: no product pairs two logs):
//   whiteness:    autocorrelation at lags 1..L against the 99 % bound
//                 2.58/sqrt(N), and the Ljung-Box Q with its chi-square p-value;
//   independence: cross-correlation of each channel's residual with each
//                 input u_j (and each other observed channel y_j) at lags
//                 -L..L against the same bound; lag k pairs r_t with v_{t-k}.
// The bound assumes the residual is white; where it is not (see whiteness),
// exceedances of the cross-correlation are indicative only. Attribution
// (attribution.h) whitens before it tests.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "trainer/residual/residuals.h"
#include "trainer/residual/statistics.h"

namespace hadynet::trainer::residual {

inline constexpr int kDefaultMaxLag = 25;
inline constexpr double kWhitenessAlpha = 0.01;  // Ljung-Box level of the whiteness verdict

// Per-log segments of the 1-step residual of y channel c, of input u_j and of
// observed channel y_j, all on the residual's rows t = 2..T-1.
Segments residual_segments(const ResidualData& data, int c);
Segments input_segments(const ResidualData& data, int j);
Segments observed_segments(const ResidualData& data, int j);

struct Whiteness {
  Eigen::VectorXd acf;    // lags 1..L
  double bound = 0;       // 2.58 / sqrt(N)
  int outside = 0;        // lags with |acf| > bound
  LjungBox ljung_box;
  bool white() const { return ljung_box.p_value >= kWhitenessAlpha; }
};
Whiteness whiteness(const Segments& residual, int max_lag);

struct CrossCorrelation {
  Eigen::VectorXd rho;  // lags -L..L (element k + L)
  double bound = 0;
  int outside = 0;      // lags with |rho| > bound
  int peak_lag = 0;     // lag of the largest |rho|
  double peak = 0;      // rho at that lag
};
CrossCorrelation cross_correlate(const Segments& residual, const Segments& input, int max_lag);

}  // namespace hadynet::trainer::residual
