#include "trainer/residual/statistics.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>

namespace hadynet::trainer::residual {

namespace {

constexpr double kEps = 1e-15;       // relative convergence of series and fractions
constexpr double kTiny = 1e-300;     // Lentz's guard against a zero denominator
constexpr int kMaxIterations = 10000;

// P(a, x) by its power series: x^a e^-x / Gamma(a+1) * sum_n x^n / ((a+1)..(a+n)).
double gamma_p_series(double a, double x) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < kMaxIterations; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * kEps) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) by the continued fraction
//   Q = x^a e^-x / Gamma(a) * 1 / (x + 1 - a - 1 (1 - a) / (x + 3 - a - 2 (2 - a) / (x + 5 - a - ...)))
// evaluated with the modified Lentz method.
double gamma_q_fraction(double a, double x) {
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < kMaxIterations; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEps) break;
  }
  return h * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// The continued fraction of I_x(a, b) (x below the mean a / (a + b) roughly):
//   I = x^a (1-x)^b / (a B(a,b)) * 1 / (1 + d1 / (1 + d2 / (1 + ...)))
//   d_{2m+1} = -(a+m)(a+b+m) x / ((a+2m)(a+2m+1)),  d_{2m} = m (b-m) x / ((a+2m-1)(a+2m))
double beta_fraction(double a, double b, double x) {
  double c = 1.0;
  double d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m < kMaxIterations; ++m) {
    const double m2 = 2.0 * m;
    double an = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));  // even step
    d = 1.0 + an * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    an = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));  // odd step
    d = 1.0 + an * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEps) break;
  }
  const double log_front = std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) +
                           b * std::log1p(-x);
  return std::exp(log_front) * h / a;
}

Eigen::VectorXd centred(const Eigen::VectorXd& v) {
  if (v.size() == 0) return v;
  return v.array() - v.mean();
}

}  // namespace

double gamma_p(double a, double x) {
  if (!(a > 0) || !(x >= 0)) {
    throw std::domain_error("gamma_p: need a > 0 and x >= 0 (a = " + std::to_string(a) +
                            ", x = " + std::to_string(x) + ")");
  }
  if (x == 0) return 0.0;
  if (std::isinf(x)) return 1.0;
  return x < a + 1.0 ? gamma_p_series(a, x) : 1.0 - gamma_q_fraction(a, x);
}

double gamma_q(double a, double x) {
  if (!(a > 0) || !(x >= 0)) {
    throw std::domain_error("gamma_q: need a > 0 and x >= 0 (a = " + std::to_string(a) +
                            ", x = " + std::to_string(x) + ")");
  }
  if (x == 0) return 1.0;
  if (std::isinf(x)) return 0.0;
  return x < a + 1.0 ? 1.0 - gamma_p_series(a, x) : gamma_q_fraction(a, x);
}

double beta_inc(double a, double b, double x) {
  if (!(a > 0) || !(b > 0) || !(x >= 0 && x <= 1)) {
    throw std::domain_error("beta_inc: need a, b > 0 and 0 <= x <= 1");
  }
  if (x == 0) return 0.0;
  if (x == 1) return 1.0;
  // The fraction converges fast for x < (a + 1) / (a + b + 2); use symmetry otherwise.
  if (x < (a + 1.0) / (a + b + 2.0)) return beta_fraction(a, b, x);
  return 1.0 - beta_fraction(b, a, 1.0 - x);
}

double chi_square_sf(double q, double dof) {
  if (!(dof > 0)) throw std::domain_error("chi_square_sf: dof must be > 0");
  if (q <= 0) return 1.0;
  return gamma_q(0.5 * dof, 0.5 * q);
}

double student_t_sf(double t, double dof) {
  if (!(dof > 0)) throw std::domain_error("student_t_sf: dof must be > 0");
  if (std::isnan(t)) return std::numeric_limits<double>::quiet_NaN();
  const double tail = 0.5 * beta_inc(0.5 * dof, 0.5, dof / (dof + t * t));  // P(T > |t|)
  return t >= 0 ? tail : 1.0 - tail;
}

double f_sf(double f, double d1, double d2) {
  if (!(d1 > 0) || !(d2 > 0)) throw std::domain_error("f_sf: degrees of freedom must be > 0");
  if (f <= 0) return 1.0;
  return beta_inc(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f));
}

long total_samples(const Segments& a) {
  long n = 0;
  for (const auto& s : a) n += static_cast<long>(s.size());
  return n;
}

long pairs_at_lag(const Segments& a, int lag) {
  long n = 0;
  for (const auto& s : a) n += std::max<long>(0, static_cast<long>(s.size()) - std::abs(lag));
  return n;
}

double correlation_bound_99(long samples) {
  return samples > 0 ? 2.58 / std::sqrt(static_cast<double>(samples)) : 0.0;
}

Eigen::VectorXd autocorrelation(const Segments& a, int max_lag) {
  Eigen::VectorXd num = Eigen::VectorXd::Zero(std::max(0, max_lag));
  double den = 0;
  for (const auto& raw : a) {
    const Eigen::VectorXd s = centred(raw);
    den += s.squaredNorm();
    const Eigen::Index n = s.size();
    for (int k = 1; k <= max_lag && k < n; ++k) num(k - 1) += s.head(n - k).dot(s.tail(n - k));
  }
  return den > 0 ? Eigen::VectorXd(num / den) : Eigen::VectorXd::Zero(num.size());
}

Eigen::VectorXd cross_correlation(const Segments& a, const Segments& b, int max_lag) {
  if (a.size() != b.size()) throw std::invalid_argument("cross_correlation: segment counts differ");
  Eigen::VectorXd num = Eigen::VectorXd::Zero(2 * max_lag + 1);
  double aa = 0, bb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].size() != b[i].size()) throw std::invalid_argument("cross_correlation: segment sizes differ");
    const Eigen::VectorXd sa = centred(a[i]), sb = centred(b[i]);
    aa += sa.squaredNorm();
    bb += sb.squaredNorm();
    const Eigen::Index n = sa.size();
    for (int k = -max_lag; k <= max_lag; ++k) {
      const Eigen::Index m = n - std::abs(k);
      if (m <= 0) continue;
      // sum_t a_t b_{t-k}: for k >= 0, a from k, b from 0; for k < 0, a from 0, b from -k.
      num(k + max_lag) += k >= 0 ? sa.segment(k, m).dot(sb.head(m)) : sa.head(m).dot(sb.segment(-k, m));
    }
  }
  const double den = std::sqrt(aa * bb);
  return den > 0 ? Eigen::VectorXd(num / den) : Eigen::VectorXd::Zero(num.size());
}

LjungBox ljung_box(const Segments& a, int max_lag) {
  const Eigen::VectorXd rho = autocorrelation(a, max_lag);
  const double n = static_cast<double>(total_samples(a));
  LjungBox lb;
  lb.dof = max_lag;
  for (int k = 1; k <= max_lag; ++k) {
    const long nk = pairs_at_lag(a, k);
    if (nk > 0) lb.q += rho(k - 1) * rho(k - 1) / static_cast<double>(nk);
  }
  lb.q *= n * (n + 2.0);
  lb.p_value = max_lag > 0 ? chi_square_sf(lb.q, max_lag) : 1.0;
  return lb;
}

DieboldMariano diebold_mariano(const Segments& loss_a, const Segments& loss_b, int bandwidth) {
  if (loss_a.size() != loss_b.size()) throw std::invalid_argument("diebold_mariano: segment counts differ");
  DieboldMariano r;
  Segments d;
  double sum = 0;
  for (std::size_t i = 0; i < loss_a.size(); ++i) {
    if (loss_a[i].size() != loss_b[i].size()) throw std::invalid_argument("diebold_mariano: segment sizes differ");
    d.push_back(loss_a[i] - loss_b[i]);
    sum += d.back().sum();
    r.samples += d.back().size();
  }
  if (r.samples < 2) return r;
  const double n = static_cast<double>(r.samples);
  r.mean = sum / n;
  // Autocovariances of d about its pooled mean, pairs inside one segment.
  const auto autocovariance = [&](int k) {
    double gamma = 0;
    for (const auto& s : d)
      for (Eigen::Index t = k; t < s.size(); ++t) gamma += (s(t) - r.mean) * (s(t - k) - r.mean);
    return gamma / n;
  };
  const double gamma0 = autocovariance(0);
  if (bandwidth >= 0) {
    r.bandwidth = bandwidth;
  } else if (gamma0 > 0) {
    // Andrews (1991), Bartlett kernel, AR(1) plug-in: S = 1.1447 (alpha N)^(1/3),
    // alpha = 4 rho^2 / ((1 - rho)^2 (1 + rho)^2); at most N / 4 lags.
    const double rho = std::clamp(autocovariance(1) / gamma0, -0.97, 0.97);
    const double alpha = 4 * rho * rho / ((1 - rho) * (1 - rho) * (1 + rho) * (1 + rho));
    r.bandwidth = static_cast<int>(std::min(std::ceil(1.1447 * std::cbrt(alpha * n)), n / 4));
  }
  double variance = 0;
  for (int k = 0; k <= r.bandwidth; ++k) {
    const double gamma = k == 0 ? gamma0 : autocovariance(k);
    const double weight = k == 0 ? 1.0 : 2.0 * (1.0 - k / (r.bandwidth + 1.0));
    variance += weight * gamma;
  }
  if (!(variance > 0)) {
    r.stat = r.mean > 0 ? std::numeric_limits<double>::infinity() : 0.0;
    r.p_value = r.mean > 0 ? 0.0 : 1.0;
    return r;
  }
  r.stat = r.mean / std::sqrt(variance / n);
  r.p_value = 0.5 * std::erfc(r.stat / std::sqrt(2.0));
  return r;
}

void relative_to_segment_level(Segments& loss_a, Segments& loss_b) {
  if (loss_a.size() != loss_b.size()) throw std::invalid_argument("relative_to_segment_level: segment counts differ");
  for (std::size_t i = 0; i < loss_a.size(); ++i) {
    if (loss_a[i].size() != loss_b[i].size())
      throw std::invalid_argument("relative_to_segment_level: segment sizes differ");
    if (loss_a[i].size() == 0) continue;
    const double level = 0.5 * (loss_a[i].mean() + loss_b[i].mean());
    if (!(level > 0)) continue;
    loss_a[i] /= level;
    loss_b[i] /= level;
  }
}

std::vector<double> holm_adjust(const std::vector<double>& p) {
  const std::size_t m = p.size();
  std::vector<std::size_t> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return p[i] < p[j]; });
  std::vector<double> adjusted(m);
  double running = 0;
  for (std::size_t r = 0; r < m; ++r) {
    const double v = std::min(1.0, static_cast<double>(m - r) * p[order[r]]);
    running = std::max(running, v);
    adjusted[order[r]] = running;
  }
  return adjusted;
}

namespace {
// Lagged design of an AR(p) fit: rows t >= p of every centred segment.
void ar_design(const Segments& x, int p, Eigen::MatrixXd& X, Eigen::VectorXd& y) {
  long rows = 0;
  for (const auto& s : x) rows += std::max<long>(0, static_cast<long>(s.size()) - p);
  X.resize(rows, p);
  y.resize(rows);
  long r = 0;
  for (const auto& raw : x) {
    const Eigen::VectorXd s = centred(raw);
    for (Eigen::Index t = p; t < s.size(); ++t, ++r) {
      y(r) = s(t);
      for (int i = 1; i <= p; ++i) X(r, i - 1) = s(t - i);
    }
  }
}
}  // namespace

Eigen::VectorXd fit_ar(const Segments& x, int order, double* noise_variance) {
  Eigen::MatrixXd X;
  Eigen::VectorXd y;
  ar_design(x, order, X, y);
  Eigen::VectorXd a = Eigen::VectorXd::Zero(order);
  if (order > 0 && X.rows() > order) a = X.colPivHouseholderQr().solve(y);
  if (noise_variance != nullptr) {
    const Eigen::VectorXd e = order > 0 ? Eigen::VectorXd(y - X * a) : y;
    *noise_variance = e.size() > 0 ? e.squaredNorm() / static_cast<double>(e.size()) : 0.0;
  }
  return a;
}

// Every order's residual sum of squares comes from one Householder QR of
// [X y] (X: the lags 1..max_order, nested): the last column of R holds
// z = Q^T y, and the fit on the first p lags leaves sum_{k >= p} z_k^2
// (k = 0..max_order). One factorisation instead of one per order (a third
// of the flops at max_order 10): choose_ar_order was 14 % of a `residual
// --fix` run's cycles (perf, stop 75). With a lag that is a combination of
// the ones before it (a rank-deficient X: a constant or exactly periodic
// residual), a zero pivot, that identity does not hold: such data take one
// column-pivoting QR per order, the fit fit_ar() makes.
namespace {
std::optional<Eigen::VectorXd> nested_rss(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  const Eigen::Index m = X.cols();
  Eigen::MatrixXd Xy(X.rows(), m + 1);
  Xy << X, y;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(Xy);
  const Eigen::MatrixXd& R = qr.matrixQR();
  for (Eigen::Index j = 0; j < m; ++j)
    if (!(std::abs(R(j, j)) > 1e-9 * std::max(X.col(j).norm(), 1e-300))) return std::nullopt;
  Eigen::VectorXd rss(m + 1);  // rss(p): the fit on lags 1..p
  double tail = 0;
  for (Eigen::Index k = m; k >= 0; --k) {
    tail += R(k, m) * R(k, m);
    rss(k) = tail;
  }
  return rss;
}

double rss_of_order(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, int p) {
  if (p == 0) return y.squaredNorm();
  const Eigen::MatrixXd Xp = X.leftCols(p);
  const Eigen::VectorXd a = Xp.colPivHouseholderQr().solve(y);
  return (y - Xp * a).squaredNorm();
}
}  // namespace

int choose_ar_order(const Segments& x, int max_order) {
  // Every order is scored on the same rows (t >= max_order) so that BIC compares like with like.
  Eigen::MatrixXd X;
  Eigen::VectorXd y;
  ar_design(x, max_order, X, y);
  const double n = static_cast<double>(y.size());
  if (n <= max_order + 1) return 0;
  const std::optional<Eigen::VectorXd> nested = nested_rss(X, y);
  int best = 0;
  double best_bic = std::numeric_limits<double>::infinity();
  for (int p = 0; p <= max_order; ++p) {
    const double sigma2 = (nested ? (*nested)(p) : rss_of_order(X, y, p)) / n;
    const double bic = n * std::log(std::max(sigma2, 1e-300)) + p * std::log(n);
    if (bic < best_bic) {
      best_bic = bic;
      best = p;
    }
  }
  return best;
}

Segments ar_filter(const Segments& x, const Eigen::VectorXd& a) {
  const auto p = a.size();
  Segments out;
  out.reserve(x.size());
  for (const auto& s : x) {
    const Eigen::Index n = std::max<Eigen::Index>(0, s.size() - p);
    Eigen::VectorXd e(n);
    for (Eigen::Index t = 0; t < n; ++t) {
      double v = s(t + p);
      for (Eigen::Index i = 1; i <= p; ++i) v -= a(i - 1) * s(t + p - i);
      e(t) = v;
    }
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace hadynet::trainer::residual
