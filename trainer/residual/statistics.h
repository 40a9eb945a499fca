// Statistics of the residual loop (docs/residual.md): distribution tails,
// correlations pooled over several logs, whiteness tests, Holm's correction
// and the small least-squares tools the attribution uses.
//
// Pooling: a "segmented" series is one Eigen vector per log. Every sum runs
// inside one segment only (no product ever pairs samples of two logs), and
// each segment is centred on its own mean (logs may have different offsets).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace hadynet::trainer::residual {

using Segments = std::vector<Eigen::VectorXd>;

// Regularised incomplete gamma functions P(a, x) = gamma(a, x) / Gamma(a) and
// Q = 1 - P, for a > 0, x >= 0 (series for x < a + 1, continued fraction
// otherwise; relative accuracy ~1e-14). Throw std::domain_error otherwise.
double gamma_p(double a, double x);
double gamma_q(double a, double x);
// Regularised incomplete beta I_x(a, b), a, b > 0, 0 <= x <= 1.
double beta_inc(double a, double b, double x);

// Upper tails: P(X > q) for X ~ chi-square(dof), P(T > t) for Student's t
// with `dof` degrees of freedom (one-sided), P(F > f) for F(d1, d2).
double chi_square_sf(double q, double dof);
double student_t_sf(double t, double dof);
double f_sf(double f, double d1, double d2);

// Pooled autocorrelation at lags 1..max_lag (element k-1 is lag k):
//   rho(k) = sum_logs sum_t a_t a_{t+k} / sum_logs sum_t a_t^2   (a centred per log)
Eigen::VectorXd autocorrelation(const Segments& a, int max_lag);

// Pooled cross-correlation at lags -max_lag..max_lag (element k + max_lag is lag k):
//   rho_ab(k) = sum a_t b_{t-k} / sqrt(sum a^2 sum b^2)
// A positive k pairs a with b k steps earlier: b leads a (e.g. an input that
// acts on a residual k steps later). Segments of a and b must have equal sizes.
Eigen::VectorXd cross_correlation(const Segments& a, const Segments& b, int max_lag);

// Number of samples in all segments; pairs at lag k: sum over logs of (n_log - k).
long total_samples(const Segments& a);
long pairs_at_lag(const Segments& a, int lag);

// The 99 % bound of a correlation of white noise: 2.58 / sqrt(N).
double correlation_bound_99(long samples);

// Ljung-Box portmanteau test of whiteness on the pooled autocorrelation:
//   Q = N (N + 2) sum_{k=1..h} rho_k^2 / n_k,   n_k = pairs at lag k
// (n_k = N - k for one log, the textbook formula), Q ~ chi-square(h) when the
// series is white.
struct LjungBox {
  double q = 0;
  int dof = 0;
  double p_value = 1;
};
LjungBox ljung_box(const Segments& a, int max_lag);

// Diebold-Mariano test of equal predictive accuracy: is model B's loss
// lower than model A's on the same rows? d_t = loss_a_t - loss_b_t, per log
// segment; the mean of d over every row is tested against 0 with a
// heteroskedasticity-and-autocorrelation-consistent variance (Newey-West:
// Bartlett weights up to `bandwidth` lags, pairs only inside one segment),
// stat = mean / sqrt(var / N) ~ N(0, 1) under equal accuracy. One-sided:
// p = P(Z > stat), small when B is better. bandwidth < 0: chosen from the
// data (Andrews 1991, the Bartlett kernel's AR(1) plug-in rule; a model's
// per-row losses are strongly autocorrelated, and the fixed rule
// floor(4 (N / 100)^(2/9)) rejected a true null 6 % of the time at 1 % on
// AR(1) differences with phi 0.8).
struct DieboldMariano {
  double mean = 0;       // mean of loss_a - loss_b (positive: B better)
  double stat = 0;
  double p_value = 1;    // one-sided, B better than A
  int bandwidth = 0;
  long samples = 0;
};
DieboldMariano diebold_mariano(const Segments& loss_a, const Segments& loss_b, int bandwidth = -1);

// Each log's losses in that log's own level: divides segment i of two
// models' per-row losses on the same rows by the pair's mean loss there,
// (mean a_i + mean b_i) / 2, so that a Diebold-Mariano test of the results
// weighs every log (and fold) by its relative difference, not by its size.
// Without it the log with the largest errors carries the test: a hard
// grasp's squared errors are ten times another's and heavy-tailed, and its
// fine-tuning noise hides a gain most logs show (docs/residual-experiments.md, "Each
// log in its own level"; --decision-pooling logs). Equal accuracy within
// each log stays equal accuracy. A segment of level 0 (or empty) is left
// as it is.
// Throws std::invalid_argument when the segments do not pair.
void relative_to_segment_level(Segments& loss_a, Segments& loss_b);

// Holm's step-down correction of a family of p-values: adjusted p-values
// (monotone, capped at 1) in the input order. Controls the family-wise error
// rate under any dependence between the tests.
std::vector<double> holm_adjust(const std::vector<double>& p_values);

// Least-squares AR(p) fit x_t = sum_i a_i x_{t-i} + e_t on segmented,
// centred data (no pair across a log boundary). Returns a (size p) and the
// residual variance through `noise_variance` (if not null).
Eigen::VectorXd fit_ar(const Segments& x, int order, double* noise_variance = nullptr);
// AR order in 0..max_order minimising BIC = n log(sigma^2) + p log(n).
int choose_ar_order(const Segments& x, int max_order);
// Applies the whitening filter e_t = x_t - sum_i a_i x_{t-i} per segment; the
// first p samples of each segment are dropped.
Segments ar_filter(const Segments& x, const Eigen::VectorXd& a);

}  // namespace hadynet::trainer::residual
