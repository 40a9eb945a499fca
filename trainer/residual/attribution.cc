#include "trainer/residual/attribution.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

#include "trainer/residual/statistics.h"

namespace hadynet::trainer::residual {

namespace {

// One part (training or held-out) of every log: centred residual and regressors.
struct Part {
  Segments r;                         // one segment per log
  std::vector<Eigen::MatrixXd> z;     // n_log x k per log
};

Eigen::MatrixXd stack(const std::vector<Eigen::MatrixXd>& parts, Eigen::Index cols) {
  Eigen::Index rows = 0;
  for (const auto& p : parts) rows += p.rows();
  Eigen::MatrixXd out(rows, cols);
  Eigen::Index r = 0;
  for (const auto& p : parts) {
    out.middleRows(r, p.rows()) = p;
    r += p.rows();
  }
  return out;
}

Eigen::VectorXd stack(const Segments& parts) {
  Eigen::Index rows = 0;
  for (const auto& p : parts) rows += p.size();
  Eigen::VectorXd out(rows);
  Eigen::Index r = 0;
  for (const auto& p : parts) {
    out.segment(r, p.size()) = p;
    r += p.size();
  }
  return out;
}

// Whitens every column of every log's regressors with the AR filter `a`.
std::vector<Eigen::MatrixXd> filter_columns(const std::vector<Eigen::MatrixXd>& z, const Eigen::VectorXd& a) {
  std::vector<Eigen::MatrixXd> out;
  for (const auto& m : z) {
    const Eigen::Index n = std::max<Eigen::Index>(0, m.rows() - a.size());
    Eigen::MatrixXd f(n, m.cols());
    for (Eigen::Index k = 0; k < m.cols(); ++k) f.col(k) = ar_filter({m.col(k)}, a).front();
    out.push_back(std::move(f));
  }
  return out;
}

Eigen::VectorXd least_squares(const Eigen::MatrixXd& z, const Eigen::VectorXd& r) {
  if (z.rows() == 0) return Eigen::VectorXd::Zero(z.cols());
  return z.colPivHouseholderQr().solve(r);
}

struct Explained {
  double share = 0;       // 1 - SS(r - Z beta) / SS(r)
  double per_sample = 0;  // (SS(r) - SS(r - Z beta)) / n
};
Explained explained(const Part& part, const Eigen::VectorXd& beta) {
  double ss = 0, ss_res = 0;
  long n = 0;
  for (std::size_t i = 0; i < part.r.size(); ++i) {
    ss += part.r[i].squaredNorm();
    ss_res += (part.r[i] - part.z[i] * beta).squaredNorm();
    n += static_cast<long>(part.r[i].size());
  }
  Explained e;
  if (ss > 0) e.share = 1.0 - ss_res / ss;
  if (n > 0) e.per_sample = (ss - ss_res) / static_cast<double>(n);
  return e;
}

// Target c's residual and the regressors `feature_of` gives each log, split
// in time at options.train_fraction into a training and a held-out part,
// each centred on the training part's means; a log with fewer than
// max_ar_order + 5 rows in either part is left out. `support` counts the
// training rows where each regressor is non-zero.
struct SplitParts {
  Part train, held;
  Eigen::Index k = 0;
  Eigen::VectorXi support;
};
template <class FeatureOf>
SplitParts split_parts(const ResidualData& data, Eigen::Index c, const FeatureOf& feature_of,
                       const AttributionOptions& options) {
  const int min_rows = options.max_ar_order + 5;
  SplitParts s;
  for (const auto& log : data.logs) {
    const Features f = feature_of(log);
    s.k = f.z.cols();
    const int n = log.size();
    const int split = static_cast<int>(options.train_fraction * n);
    const int t0 = f.first_valid, t1 = split, h0 = std::max(split, f.first_valid), h1 = n;
    if (t1 - t0 < min_rows || h1 - h0 < min_rows) continue;
    const Eigen::VectorXd r = log.r.row(c).transpose();
    if (s.support.size() != s.k) s.support = Eigen::VectorXi::Zero(s.k);
    s.support += (f.z.middleRows(t0, t1 - t0).array().abs() > 1e-12).cast<int>().matrix().colwise().sum().transpose();
    const double mr = r.segment(t0, t1 - t0).mean();
    const Eigen::RowVectorXd mz = f.z.middleRows(t0, t1 - t0).colwise().mean();
    s.train.r.push_back(r.segment(t0, t1 - t0).array() - mr);
    s.train.z.push_back(f.z.middleRows(t0, t1 - t0).rowwise() - mz);
    s.held.r.push_back(r.segment(h0, h1 - h0).array() - mr);
    s.held.z.push_back(f.z.middleRows(h0, h1 - h0).rowwise() - mz);
  }
  return s;
}

// Cochrane-Orcutt on the training part: OLS, AR(p) on its residual (p by
// BIC), whitened OLS; twice. Returns the coefficients; `a` the AR filter,
// `ar_order` its order.
Eigen::VectorXd cochrane_orcutt(const Part& train, Eigen::Index k, const AttributionOptions& options,
                                Eigen::VectorXd& a, int& ar_order) {
  Eigen::VectorXd beta = least_squares(stack(train.z, k), stack(train.r));
  for (int pass = 0; pass < 2; ++pass) {
    Segments e;
    for (std::size_t i = 0; i < train.r.size(); ++i) e.push_back(train.r[i] - train.z[i] * beta);
    ar_order = choose_ar_order(e, options.max_ar_order);
    a = fit_ar(e, ar_order);
    beta = least_squares(stack(filter_columns(train.z, a), k), stack(ar_filter(train.r, a)));
  }
  return beta;
}

// The held-out test of a fixed prediction: the (whitened) residual `r_w`
// regressed on the (whitened) prediction `p_w`, an intercept per log. t of
// the slope (0 where the prediction is flat) and the rows used.
struct HeldOutSlope {
  double t = 0, p = 1;
  long n = 0;
};
HeldOutSlope held_out_slope(const Segments& r_w, const Segments& p_w) {
  double sxy = 0, sxx = 0, syy = 0;
  long n = 0;
  for (std::size_t i = 0; i < r_w.size(); ++i) {
    if (r_w[i].size() < 2) continue;
    const Eigen::VectorXd pc = p_w[i].array() - p_w[i].mean();
    const Eigen::VectorXd rc = r_w[i].array() - r_w[i].mean();
    sxy += pc.dot(rc);
    sxx += pc.squaredNorm();
    syy += rc.squaredNorm();
    n += static_cast<long>(rc.size());
  }
  HeldOutSlope out;
  out.n = n;
  const double dof = static_cast<double>(n) - static_cast<double>(r_w.size()) - 1.0;
  if (sxx > 1e-12 * std::max(1.0, syy) && syy > 0 && dof > 0) {
    const double slope = sxy / sxx;
    const double ss_res = std::max(syy - slope * sxy, 1e-300);
    const double se = std::sqrt(ss_res / dof / sxx);
    out.t = slope / se;
    out.p = student_t_sf(out.t, dof);
  }
  return out;
}

}  // namespace

HypothesisResult test_hypothesis(const ResidualData& data, const Hypothesis& h, const AttributionOptions& options) {
  HypothesisResult res;
  res.hypothesis = h;
  res.effect = effect_info(h.kind).name;
  const auto c = static_cast<Eigen::Index>(h.target);
  SplitParts parts = split_parts(data, c, [&](const ResidualLog& log) { return features(h, log); }, options);
  const Part& train = parts.train;
  const Part& held = parts.held;
  const Eigen::Index k = parts.k;
  const Eigen::VectorXi& support = parts.support;
  res.coef = Eigen::VectorXd::Zero(k);
  if (train.r.empty()) {
    res.testable = false;
    res.label = describe(h, data, res.coef) + " (logs too short)";
    return res;
  }
  Eigen::VectorXd spread = Eigen::VectorXd::Zero(k);
  long training_rows = 0;
  for (const auto& z : train.z) {
    spread += z.colwise().squaredNorm().transpose();
    training_rows += z.rows();
  }
  for (Eigen::Index j = 0; j < k; ++j) {
    if (support(j) >= options.min_support && spread(j) > 1e-18) continue;
    res.testable = false;
    std::string why = "a regressor is constant in the training part";
    if (support(j) < options.min_support) {
      const char* nonzero = effect_info(h.kind).support_phrase;
      why = std::string(nonzero ? nonzero : "a regressor is non-zero") + " in " + std::to_string(support(j)) +
            " of " + std::to_string(training_rows) + " training rows, at least " +
            std::to_string(options.min_support) + " needed";
    }
    res.label = describe(h, data, res.coef) + " (not testable: " + why + ")";
    return res;
  }

  Eigen::VectorXd a;
  const Eigen::VectorXd beta = cochrane_orcutt(train, k, options, a, res.ar_order);
  res.coef = beta;
  res.parameter = main_parameter(h, beta);
  res.plausible = plausible(h, beta);
  res.label = describe(h, data, beta);
  res.explained_train = explained(train, beta).share;
  const Explained e_held = explained(held, beta);
  res.explained = e_held.share;
  const double scale = data.y_scale(c);
  res.explained_std = e_held.per_sample / (scale * scale);

  // Held-out test: whitened residual against the whitened fixed prediction, an intercept per log.
  const Segments r_w = ar_filter(held.r, a);
  const std::vector<Eigen::MatrixXd> z_w = filter_columns(held.z, a);
  Segments p_w;
  for (const auto& z : z_w) p_w.push_back(z * beta);
  long n_train = 0;
  for (const auto& s : ar_filter(train.r, a)) n_train += static_cast<long>(s.size());
  res.n_train = n_train;
  const HeldOutSlope slope = held_out_slope(r_w, p_w);
  res.n_held_out = slope.n;
  res.t_stat = slope.t;
  res.p_value = slope.p;
  return res;
}

std::array<double, 2> partial_held_out_t(const ResidualData& data, const Hypothesis& first, const Hypothesis& second,
                                         const AttributionOptions& options) {
  if (first.target != second.target) throw std::logic_error("partial_held_out_t: two targets");
  Eigen::Index k_first = 0;
  const SplitParts parts = split_parts(
      data, static_cast<Eigen::Index>(first.target),
      [&](const ResidualLog& log) {
        const Features a = features(first, log), b = features(second, log);
        k_first = a.z.cols();
        Features f;
        f.z.resize(a.z.rows(), a.z.cols() + b.z.cols());
        f.z << a.z, b.z;
        f.first_valid = std::max(a.first_valid, b.first_valid);
        return f;
      },
      options);
  if (parts.train.r.empty()) return {0.0, 0.0};
  Eigen::VectorXd a;
  int ar_order = 0;
  const Eigen::VectorXd beta = cochrane_orcutt(parts.train, parts.k, options, a, ar_order);
  const Segments r_w = ar_filter(parts.held.r, a);
  const std::vector<Eigen::MatrixXd> z_w = filter_columns(parts.held.z, a);
  std::array<double, 2> t{};
  for (int side = 0; side < 2; ++side) {
    const Eigen::Index from = side == 0 ? 0 : k_first, cols = side == 0 ? k_first : parts.k - k_first;
    const Eigen::Index other_from = side == 0 ? k_first : 0, other_cols = parts.k - cols;
    Segments own, rest;
    for (std::size_t i = 0; i < z_w.size(); ++i) {
      own.push_back(z_w[i].middleCols(from, cols) * beta.segment(from, cols));
      rest.push_back(r_w[i] - z_w[i].middleCols(other_from, other_cols) * beta.segment(other_from, other_cols));
    }
    t[static_cast<std::size_t>(side)] = held_out_slope(rest, own).t;
  }
  return t;
}

std::optional<HypothesisResult> Attribution::winner() const {
  if (ranked.empty() || !ranked.front().significant) return std::nullopt;
  return ranked.front();
}

std::vector<HypothesisResult> Attribution::winner_family() const {
  const auto w = winner();
  return w ? family_of(*w) : std::vector<HypothesisResult>{};
}

std::vector<HypothesisResult> Attribution::family_of(const HypothesisResult& lead) const {
  std::vector<HypothesisResult> out;
  const HypothesisResult* w = &lead;
  std::map<int, bool> seen;
  for (const auto& r : ranked) {
    if (!r.significant) break;
    // The same effect with the same delay (0 for the effects without one).
    if (r.hypothesis.kind != w->hypothesis.kind || r.hypothesis.delay != w->hypothesis.delay) continue;
    if (seen[r.hypothesis.target]) continue;
    seen[r.hypothesis.target] = true;
    out.push_back(r);
  }
  return out;
}

NullCalibration calibrate_null(const ResidualData& data, const ResidualData& reference,
                               const std::vector<Hypothesis>& hypotheses, const AttributionOptions& options) {
  if (reference.y_names != data.y_names || reference.u_names != data.u_names ||
      reference.aux_names != data.aux_names) {
    throw std::invalid_argument("the reference logs' channels (y, u and aux_* columns) differ from the logs "
                                "under test; a null must be recorded with the same channels");
  }
  NullCalibration null;
  null.logs = static_cast<long>(reference.logs.size());
  const auto ny = static_cast<Eigen::Index>(reference.y_names.size());
  null.residual_level = Eigen::VectorXd::Zero(ny);
  for (Eigen::Index c = 0; c < ny; ++c) {
    double ss = 0;
    long n = 0;
    for (const auto& log : reference.logs) {
      const int rows = log.size();
      const int split = static_cast<int>(options.train_fraction * rows);
      if (split < 1 || rows - split < 1) continue;
      const Eigen::VectorXd r = log.r.row(c).transpose();
      const double mean = r.head(split).mean();
      ss += (r.segment(split, rows - split).array() - mean).square().sum();
      n += rows - split;
    }
    const double scale = reference.y_scale(c);
    if (n > 0) null.residual_level(c) = ss / static_cast<double>(n) / (scale * scale);
  }
  null.explained_std.reserve(hypotheses.size());
  for (const auto& h : hypotheses) {
    const HypothesisResult r = test_hypothesis(reference, h, options);
    null.explained_std.push_back(r.testable ? std::max(0.0, r.explained_std) : 0.0);
  }
  return null;
}

double floor_statistic(const Attribution& attribution, const HypothesisResult& result) {
  return attribution.null ? result.excess_share : result.explained_std;
}

double floor_of(const AttributionOptions& options, bool with_null) {
  return with_null ? options.min_excess_null : options.min_explained_std;
}

namespace {

// Steps 4 and 5 on att.ranked's tested results (p_adjusted set): which are
// significant under att.options' floors, and their order.
void mark_and_rank(Attribution& att) {
  const AttributionOptions& options = att.options;
  for (auto& r : att.ranked) {
    const bool upper_rail = r.hypothesis.kind == EffectKind::kSaturation && r.hypothesis.side > 0;
    const bool uses_rail_floor = att.null && upper_rail && options.upper_rail_floor_applies();
    const bool above_floor = uses_rail_floor ? r.excess_share >= *options.upper_rail_floor
                                        : floor_statistic(att, r) >= floor_of(options, att.null.has_value());
    r.significant =
        r.testable && r.p_adjusted < options.alpha && r.explained >= options.min_explained && above_floor && r.plausible;
  }
  std::stable_sort(att.ranked.begin(), att.ranked.end(), [&att](const HypothesisResult& a, const HypothesisResult& b) {
    if (a.significant != b.significant) return a.significant;
    if (a.significant) return floor_statistic(att, a) > floor_statistic(att, b);
    return a.p_value < b.p_value;
  });
}

}  // namespace

Attribution attribute(const ResidualData& data, const std::vector<Hypothesis>& hypotheses,
                      const AttributionOptions& options, const NullCalibration* null) {
  Attribution att;
  att.options = options;
  if (null != nullptr) {
    if (null->explained_std.size() != hypotheses.size())
      throw std::invalid_argument("attribute: the null was calibrated for other hypotheses");
    att.null = *null;
  }
  std::vector<HypothesisResult> results;
  results.reserve(hypotheses.size());
  for (std::size_t i = 0; i < hypotheses.size(); ++i) {
    results.push_back(test_hypothesis(data, hypotheses[i], options));
    auto& r = results.back();
    r.null_explained_std = null != nullptr ? null->explained_std[i] : 0.0;
    r.excess_std = r.explained_std - r.null_explained_std;
    if (null != nullptr) {
      const double level = null->residual_level(r.hypothesis.target);
      r.excess_share = level > 0 ? r.excess_std / level : 0.0;
    }
  }
  // The family: every testable hypothesis (an untestable one has no p-value).
  std::vector<double> p;
  std::vector<std::size_t> family;
  for (std::size_t i = 0; i < results.size(); ++i) {
    if (!results[i].testable) continue;
    family.push_back(i);
    p.push_back(results[i].p_value);
  }
  att.tested = static_cast<long>(family.size());
  const std::vector<double> adjusted = holm_adjust(p);
  for (std::size_t f = 0; f < family.size(); ++f) results[family[f]].p_adjusted = adjusted[f];
  att.ranked = std::move(results);
  mark_and_rank(att);
  return att;
}

namespace {

// `attribution` with its options changed by `change(options)`, significance
// and ranking recomputed; without a null, `attribution` unchanged.
template <class Change>
Attribution refloored(const Attribution& attribution, Change change) {
  if (!attribution.null) return attribution;
  Attribution att = attribution;
  change(att.options);
  mark_and_rank(att);
  return att;
}

}  // namespace

Attribution with_null_floor(const Attribution& attribution, double min_excess_null) {
  return refloored(attribution, [&](AttributionOptions& o) { o.min_excess_null = min_excess_null; });
}

Attribution with_upper_rail_floor(const Attribution& attribution, double floor) {
  return refloored(attribution, [&](AttributionOptions& o) { o.upper_rail_floor = floor; });
}

}  // namespace hadynet::trainer::residual
