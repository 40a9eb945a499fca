// The analysis part of `hadynet residual`'s outputs (cli/residual_report.h).
#include "cli/residual_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "cli/gnuplot.h"
#include "cli/number_text.h"
#include "cli/residual_fix_report.h"

namespace hadynet::cli {

namespace rs = trainer::residual;
using nlohmann::json;

namespace {

std::vector<double> to_vector(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

// {name: value} for per-channel values in `names`' order.
json by_channel(const std::vector<std::string>& names, const Eigen::VectorXd& v) {
  json out = json::object();
  for (std::size_t c = 0; c < names.size() && static_cast<Eigen::Index>(c) < v.size(); ++c)
    out[names[c]] = v(static_cast<Eigen::Index>(c));
  return out;
}

json hypothesis_json(const rs::ResidualData& data, const rs::HypothesisResult& r) {
  const auto& h = r.hypothesis;
  json j = {{"effect", r.effect},
            {"label", r.label},
            {"target", data.y_names[static_cast<std::size_t>(h.target)]},
            {"parameter", r.parameter},
            {"coefficients", to_vector(r.coef)},
            {"explained", r.explained},
            {"explained_train", r.explained_train},
            {"explained_std", r.explained_std},
            {"null_explained_std", r.null_explained_std},
            {"excess_std", r.excess_std},
            {"excess_share", r.excess_share},
            {"t", r.t_stat},
            {"p_value", r.p_value},
            {"p_adjusted", r.p_adjusted},
            {"significant", r.significant},
            {"testable", r.testable}, {"plausible", r.plausible},
            {"ar_order", r.ar_order},
            {"n_train", r.n_train},
            {"n_held_out", r.n_held_out}};
  // The hypothesis' own parameters, whatever its effect: a delay, a source
  // channel (its effect's SourceKind), a rail (effects.h: 0 / none otherwise).
  if (h.delay > 0) j["delay_steps"] = h.delay;
  if (const std::string source = rs::source_name(h, data); !source.empty()) j["source"] = source;
  if (h.side != 0) {
    j["rail"] = h.rail;
    j["side"] = h.side > 0 ? "upper" : "lower";
  }
  return j;
}

// ---- plots ----

std::string grid_header(const std::string& png, std::size_t panels, const std::string& title, int& rows) {
  const int cols = 4;
  rows = static_cast<int>((panels + cols - 1) / cols);
  return "set terminal pngcairo size 1600," + std::to_string(170 * rows + 60) + " font 'sans,8' noenhanced\n" +
         "set output " + gnuplot_quote(png) + "\nset multiplot layout " + std::to_string(rows) + "," +
         std::to_string(cols) + " title " + gnuplot_quote(title) + "\nset grid\nset key off\n";
}

}  // namespace

nlohmann::json analysis_json(const rs::Analysis& a, const std::string& model_path, const std::string& pb_choice) {
  const auto& d = a.data;
  json logs = json::array();
  for (const auto& log : d.logs) {
    logs.push_back({{"file", log.seq.file},
                    {"state", log.seq.state},
                    {"rows", log.seq.steps()},
                    {"pb_source", log.pb_source},
                    {"pb_check", log.pb_check.checked
                                     ? json{{"stored_loss", log.pb_check.stored_loss},
                                            {"adapted_loss", log.pb_check.adapted_loss},
                                            {"stored_channel_loss", by_channel(d.y_names, log.pb_check.stored_channel_loss)},
                                            {"adapted_channel_loss", by_channel(d.y_names, log.pb_check.adapted_channel_loss)},
                                            {"channel_ratio", log.pb_check.channel_ratio},
                                            {"margin", rs::kStoredPbMargin},
                                            {"replaced", log.pb_check.replace}}
                                     : json(nullptr)},
                    {"pb", std::vector<float>(log.pb.data(), log.pb.data() + log.pb.size())}});
  }
  json fit = json::object(), rmse = json::object();
  for (std::size_t c = 0; c < d.y_names.size(); ++c) {
    const auto row = static_cast<Eigen::Index>(c);
    fit[d.y_names[c]] = to_vector(a.horizon.fit.row(row).transpose());
    rmse[d.y_names[c]] = to_vector(a.horizon.rmse.row(row).transpose());
  }
  json white = json::array(), inputs = json::array(), observed = json::array();
  for (std::size_t c = 0; c < d.y_names.size(); ++c) {
    const auto& w = a.whiteness[c];
    white.push_back({{"channel", d.y_names[c]},
                     {"acf", to_vector(w.acf)},
                     {"bound", w.bound},
                     {"outside", w.outside},
                     {"ljung_box", {{"q", w.ljung_box.q}, {"dof", w.ljung_box.dof}, {"p_value", w.ljung_box.p_value}}},
                     {"white", w.white()}});
    for (std::size_t j = 0; j < d.u_names.size(); ++j) {
      const auto& x = a.with_inputs[c][j];
      inputs.push_back({{"channel", d.y_names[c]}, {"input", d.u_names[j]}, {"rho", to_vector(x.rho)},
                        {"outside", x.outside}, {"peak_lag", x.peak_lag}, {"peak", x.peak}});
    }
    for (std::size_t j = 0; j < d.y_names.size(); ++j) {
      if (j == c) continue;
      const auto& x = a.with_observed[c][j];
      observed.push_back({{"channel", d.y_names[c]}, {"input", d.y_names[j]}, {"rho", to_vector(x.rho)},
                          {"outside", x.outside}, {"peak_lag", x.peak_lag}, {"peak", x.peak}});
    }
  }
  const auto& att = a.attribution;
  json ranked = json::array();
  for (const auto& r : att.ranked) ranked.push_back(hypothesis_json(d, r));
  json family = json::array();
  for (const auto& r : att.winner_family()) family.push_back(hypothesis_json(d, r));
  json library = json::array();
  for (const auto& e : rs::effect_library()) {
    library.push_back({{"name", e.name}, {"feature", e.feature}, {"parameter", e.parameter},
                       {"augmentation", e.augmentation}});
  }
  const auto w = att.winner();
  json null_json = nullptr;
  if (att.null) {
    null_json = {{"logs", att.null->logs},
                 {"pb_summary", a.reference_pb},
                 {"residual_level", by_channel(d.y_names, att.null->residual_level)}};
  }
  return {{"model", model_path},
          {"pb", pb_choice},
          {"pb_summary", rs::pb_summary(d, pb_choice)},
          {"logs", logs},
          {"channels", d.y_names},
          {"inputs", d.u_names},
          {"aux", d.aux_names},
          {"verdict", a.verdict},
          {"multi_step", {{"horizon", a.horizon.horizon}, {"windows", a.horizon.samples}, {"fit_percent", fit},
                          {"rmse", rmse}}},
          {"whiteness", {{"max_lag", a.max_lag}, {"alpha", rs::kWhitenessAlpha}, {"channels", white}}},
          {"independence", {{"max_lag", a.max_lag}, {"inputs", inputs}, {"observed", observed}}},
          {"attribution",
           {{"train_fraction", att.options.train_fraction},
            {"max_ar_order", att.options.max_ar_order},
            {"alpha", att.options.alpha},
            {"min_explained", att.options.min_explained},
            {"min_explained_std", att.options.min_explained_std},
            {"min_excess_null", att.options.min_excess_null},
            {"null", null_json},
            {"floors", rs::floors_summary(a)},
            {"tested", att.tested},
            {"winner", w ? hypothesis_json(d, *w) : json(nullptr)},
            {"winner_family", family},
            {"ranked", ranked}}},
          {"effect_library", library}};
}

std::string residual_trace_plot(const rs::ResidualData& d, const std::string& png) {
  std::string s;
  for (std::size_t c = 0; c < d.y_names.size(); ++c) {
    s += "$r" + std::to_string(c) + " << EOD\n";
    long x = 0;
    for (const auto& log : d.logs) {
      for (Eigen::Index j = 0; j < log.r.cols(); ++j, ++x) s += std::to_string(x) + " " + num("%.6g", log.r(static_cast<Eigen::Index>(c), j)) + "\n";
      s += "\n";  // a gap at each log boundary
    }
    s += "EOD\n";
  }
  int rows = 0;
  s += grid_header(png, d.y_names.size(), "1-step residual y - y_hat per channel (logs one after another)", rows);
  for (std::size_t c = 0; c < d.y_names.size(); ++c)
    s += "set title " + gnuplot_quote(d.y_names[c]) + "\nplot $r" + std::to_string(c) + " using 1:2 with lines lw 1\n";
  s += "unset multiplot\n";
  return run_gnuplot(s, png);
}

std::string acf_plot(const rs::Analysis& a, const std::string& png) {
  const auto& d = a.data;
  std::string s;
  for (std::size_t c = 0; c < d.y_names.size(); ++c) {
    s += "$a" + std::to_string(c) + " << EOD\n";
    for (Eigen::Index k = 0; k < a.whiteness[c].acf.size(); ++k)
      s += std::to_string(k + 1) + " " + num("%.6g", a.whiteness[c].acf(k)) + "\n";
    s += "EOD\n";
  }
  int rows = 0;
  s += grid_header(png, d.y_names.size(), "autocorrelation of the 1-step residual, 99 % bounds +-2.58/sqrt(N)", rows);
  s += "set xrange [0:" + std::to_string(a.max_lag + 1) + "]\n";
  for (std::size_t c = 0; c < d.y_names.size(); ++c) {
    const auto& w = a.whiteness[c];
    const std::string b = num("%.6g", w.bound);
    s += "set title " + gnuplot_quote(d.y_names[c] + " (Ljung-Box p " + num("%.2g", w.ljung_box.p_value) + ")") + "\n";
    s += "plot $a" + std::to_string(c) + " using 1:2 with impulses lw 2, " + b + " with lines dt 2 lc rgb 'red', -" + b +
         " with lines dt 2 lc rgb 'red'\n";
  }
  s += "unset multiplot\n";
  return run_gnuplot(s, png);
}

std::string winner_plot(const rs::Analysis& a, const rs::HypothesisResult& r, bool significant, const std::string& png) {
  const auto& d = a.data;
  const int c = r.hypothesis.target;
  const rs::Segments res = rs::residual_segments(d, c);
  const rs::Segments fit = rs::fitted_segments(d, r);
  const rs::CrossCorrelation x = rs::cross_correlate(res, fit, a.max_lag);
  std::string s = "$x << EOD\n";
  for (Eigen::Index k = 0; k < x.rho.size(); ++k) s += std::to_string(k - a.max_lag) + " " + num("%.6g", x.rho(k)) + "\n";
  s += "EOD\n$t << EOD\n";
  long n = 0;
  for (std::size_t i = 0; i < res.size(); ++i) {
    for (Eigen::Index j = 0; j < res[i].size(); ++j, ++n)
      s += std::to_string(n) + " " + num("%.6g", res[i](j)) + " " + num("%.6g", fit[i](j)) + "\n";
    s += "\n";
  }
  s += "EOD\n";
  s += "set terminal pngcairo size 1400,700 font 'sans,9' noenhanced\nset output " + gnuplot_quote(png) + "\n";
  s += "set multiplot layout 2,1 title " +
       gnuplot_quote((significant ? "winner: " : "best (not significant): ") + r.label) + "\nset grid\n";
  const std::string b = num("%.6g", x.bound);
  s += "set title " + gnuplot_quote("cross-correlation of the residual of " + d.y_names[static_cast<std::size_t>(c)] +
                                    " with the hypothesis' fitted regressor (lag k: regressor k steps earlier)") + "\n";
  s += "set xlabel 'lag (steps)'\nplot $x using 1:2 with impulses lw 2 title 'rho', " + b +
       " with lines dt 2 lc rgb 'red' title '99 %', -" + b + " with lines dt 2 lc rgb 'red' notitle\n";
  s += "set title 'residual and the fitted effect'\nset xlabel 'sample (logs one after another)'\n";
  s += "plot $t using 1:2 with lines lw 1 title 'residual', $t using 1:3 with lines lw 1 title 'fitted effect'\n";
  s += "unset multiplot\n";
  return run_gnuplot(s, png);
}

std::string ranking_plot(const rs::Analysis& a, const std::string& png) {
  const auto& ranked = a.attribution.ranked;
  std::vector<const rs::HypothesisResult*> top;
  for (const auto& r : ranked)
    if (r.testable) top.push_back(&r);
  const auto stat = [&a](const rs::HypothesisResult* r) { return rs::floor_statistic(a.attribution, *r); };
  std::stable_sort(top.begin(), top.end(), [&stat](auto* x, auto* y) { return stat(x) > stat(y); });
  if (top.size() > 20) top.resize(20);
  std::string s = "$b << EOD\n";
  for (std::size_t i = 0; i < top.size(); ++i) {
    std::string label = top[i]->label;
    for (char& ch : label)
      if (ch == '"') ch = '\'';
    s += std::to_string(i) + " " + num("%.6g", std::max(0.0, stat(top[i]))) + " " +
         (top[i]->significant ? "1" : "0") + " \"" + label + "\"\n";
  }
  s += "EOD\n";
  s += "set terminal pngcairo size 1400,700 font 'sans,9' noenhanced\nset output " + gnuplot_quote(png) + "\n";
  const bool null = a.attribution.null.has_value();
  s += "set title " + gnuplot_quote(std::string(null ? "hypotheses by held-out explained variance beyond the calibrated null, "
                                                            "in the channel's clean residual levels"
                                                     : "hypotheses by held-out explained variance (standardised units)") +
                                    "; green: significant (Holm-corrected p < " +
                                    num("%g", a.attribution.options.alpha) + ", above both floors)") + "\n";
  s += "set style fill solid 0.8\nset boxwidth 0.7\nset grid x\nset yrange [" + std::to_string(top.size()) +
       ":-1]\nset ytics font 'sans,8'\nset key off\n";
  const double floor = rs::floor_of(a.attribution.options, null);
  s += "set arrow from " + num("%g", floor) + ",-1 to " + num("%g", floor) + "," + std::to_string(top.size()) +
       " nohead dt 2 lc rgb 'red'\n";
  s += "plot $b using (0.5*$2):1:(0.5*$2):(0.35):($3 > 0 ? 0x2ca02c : 0x999999):ytic(4) with boxxyerror lc rgb variable\n";
  return run_gnuplot(s, png);
}

// ---- Markdown ----

std::string markdown(const rs::Analysis& a, const std::string& model_path, const std::string& pb_choice,
                     const std::vector<std::string>& pngs) {
  const auto& d = a.data;
  const auto& att = a.attribution;
  std::string m = "# Residual analysis\n\n";
  m += "Model `" + model_path + "`, " + std::to_string(d.logs.size()) + " logs; " + rs::pb_summary(d, pb_choice) +
       " (docs/residual.md explains every number).\n\n";
  m += "## Verdict\n\n**" + a.verdict + "**\n\n";
  const auto family = att.winner_family();
  if (!family.empty()) {
    m += "The same effect is significant on:\n\n| hypothesis | held-out explained (share) | standardised | p (Holm) |\n|---|---|---|---|\n";
    for (const auto& r : family)
      m += "| " + r.label + " | " + num("%.3f", r.explained) + " | " + num("%.4f", r.explained_std) + " | " +
           num("%.2g", r.p_adjusted) + " |\n";
    m += "\n";
  }
  m += "## Logs\n\n| log | state | rows | PB |\n|---|---|---|---|\n";
  for (const auto& log : d.logs)
    m += "| " + log.seq.file + " | " + log.seq.state + " | " + std::to_string(log.seq.steps()) + " | " + log.pb_source + " |\n";
  m += "\n## Multi-step fit\n\nfit = 100 (1 - ||y - y_hat|| / ||y - mean(y)||) over " + std::to_string(a.horizon.samples) +
       " window starts, h steps ahead.\n\n| channel | fit h=1 (%) | RMSE h=1 | fit h=" + std::to_string(a.horizon.horizon) +
       " (%) | RMSE h=" + std::to_string(a.horizon.horizon) + " |\n|---|---|---|---|---|\n";
  const Eigen::Index H = a.horizon.horizon - 1;
  for (std::size_t c = 0; c < d.y_names.size(); ++c) {
    const auto r = static_cast<Eigen::Index>(c);
    m += "| " + d.y_names[c] + " | " + num("%.1f", a.horizon.fit(r, 0)) + " | " + num("%.4g", a.horizon.rmse(r, 0)) + " | " +
         num("%.1f", a.horizon.fit(r, H)) + " | " + num("%.4g", a.horizon.rmse(r, H)) + " |\n";
  }
  m += "\n## Residual tests (1-step residuals)\n\nBound " + num("%.4f", a.whiteness.empty() ? 0.0 : a.whiteness[0].bound) +
       " (99 %, 2.58/sqrt(N)); Ljung-Box over lags 1.." + std::to_string(a.max_lag) +
       ", white when p >= 0.01. Cross-correlation with the inputs over lags -" + std::to_string(a.max_lag) + ".." +
       std::to_string(a.max_lag) + " (positive lag: input earlier); largest |rho| shown.\n\n"
       "| channel | Ljung-Box Q | p | white | acf lags outside | input with largest |rho| | lag | rho | lags outside (all inputs) |\n"
       "|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t c = 0; c < d.y_names.size(); ++c) {
    const auto& w = a.whiteness[c];
    std::size_t best = 0;
    int outside = 0;
    for (std::size_t j = 0; j < d.u_names.size(); ++j) {
      outside += a.with_inputs[c][j].outside;
      if (std::abs(a.with_inputs[c][j].peak) > std::abs(a.with_inputs[c][best].peak)) best = j;
    }
    const bool has_inputs = !d.u_names.empty();
    m += "| " + d.y_names[c] + " | " + num("%.1f", w.ljung_box.q) + " | " + num("%.2g", w.ljung_box.p_value) + " | " +
         (w.white() ? "yes" : "no") + " | " + std::to_string(w.outside) + " | " + (has_inputs ? d.u_names[best] : "-") +
         " | " + (has_inputs ? std::to_string(a.with_inputs[c][best].peak_lag) : "-") + " | " +
         (has_inputs ? num("%.3f", a.with_inputs[c][best].peak) : "-") + " | " + std::to_string(outside) + " |\n";
  }
  m += "\n## Attribution\n\nEach hypothesis is fitted (least squares with AR errors, Cochrane-Orcutt) on the first " +
       num("%.0f", 100 * att.options.train_fraction) +
       " % of each log and tested on the rest: one-sided t-test of the whitened held-out residual on the fixed "
       "prediction, Holm-corrected over the " + std::to_string(att.tested) + " testable hypotheses (alpha " +
       num("%g", att.options.alpha) + "). Significant also requires a held-out explained share >= " +
       num("%g", att.options.min_explained) +
       (att.null ? " and, beyond what the same hypothesis explains on the calibrated null, >= " +
                       num("%g", att.options.min_excess_null) +
                       " times its channel's clean residual level there. Ranked by that excess. " +
                       rs::floors_summary(a) + ".\n\n"
                 : " and >= " + num("%g", att.options.min_explained_std) +
                       " in standardised units. Ranked by the latter. " + rs::floors_summary(a) + ".\n\n") +
       "| rank | hypothesis | effect | held-out explained (share) | standardised | on the null | excess / clean level | train share | t | p (Holm) | status |\n"
       "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < att.ranked.size() && i < 20; ++i) {
    const auto& r = att.ranked[i];
    m += "| " + std::to_string(i + 1) + " | " + r.label + " | " + r.effect + " | " + num("%.3f", r.explained) + " | " +
         num("%.4f", r.explained_std) + " | " + (att.null ? num("%.4f", r.null_explained_std) : std::string("-")) +
         " | " + (att.null ? num("%.2f", r.excess_share) : std::string("-")) + " | " + num("%.3f", r.explained_train) + " | " + num("%.1f", r.t_stat) + " | " +
         num("%.2g", r.p_adjusted) + " | " + rs::hypothesis_status(r, att.options) + " |\n";
  }
  m += "\n## Effect library\n\n| effect | feature test | parameter | augmentation (--fix) |\n|---|---|---|---|\n";
  for (const auto& e : rs::effect_library())
    m += std::string("| ") + e.name + " | " + e.feature + " | " + e.parameter + " | " + e.augmentation + " |\n";
  if (!pngs.empty()) {
    m += "\n## Plots\n\n";
    for (const auto& p : pngs) m += "![" + p + "](" + p + ")\n\n";
  }
  return m;
}

void write_report(const std::filesystem::path& dir, const rs::Analysis& a, const std::string& model_path,
                  const std::string& pb_choice, const rs::FixResult* fixed, const rs::FixOptions& fix_options,
                  const std::string& written) {
  std::vector<std::string> pngs;
  auto plot = [&](const std::string& name, const std::string& err) {
    if (!err.empty()) throw std::runtime_error(err);
    pngs.push_back(name);
  };
  plot("residuals.png", residual_trace_plot(a.data, (dir / "residuals.png").string()));
  plot("autocorrelation.png", acf_plot(a, (dir / "autocorrelation.png").string()));
  if (const rs::HypothesisResult* shown = rs::hypothesis_to_show(a.attribution))
    plot("winner.png", winner_plot(a, *shown, shown->significant, (dir / "winner.png").string()));
  plot("ranking.png", ranking_plot(a, (dir / "ranking.png").string()));
  const std::string md_path = (dir / "REPORT.md").string();
  std::ofstream md(md_path);
  if (!md) throw std::runtime_error(md_path + ": cannot write");
  md << markdown(a, model_path, pb_choice, pngs);
  std::string fix_png;
  if (fixed != nullptr && fixed->tried) {
    plot("fix.png", fix_plot(*fixed, (dir / "fix.png").string()));
    pngs.pop_back();  // shown in the Fix section
    fix_png = "fix.png";
  }
  if (fixed != nullptr) md << fix_markdown(*fixed, fix_options, written, fix_png);
  if (!md) throw std::runtime_error(md_path + ": write failed");
  std::fprintf(stderr, "wrote %s\n", md_path.c_str());
}

}  // namespace hadynet::cli
