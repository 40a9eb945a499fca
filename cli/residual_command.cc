// hadynet residual: the analysis half of the residual loop (docs/residual.md,
// DESIGN.md section 5): multi-step residuals of a model over logs, the
// residual tests (whiteness, independence), the effect library's feature
// tests and their attribution, a Markdown report with PNG plots and a JSON
// with every number.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/gnuplot.h"
#include "cli/number_text.h"
#include "cli/options.h"
#include "cli/residual_fix_report.h"
#include "datalog/log_reader.h"
#include "trainer/model_file.h"
#include "trainer/residual/attribution.h"
#include "trainer/residual/augment.h"
#include "trainer/residual/residuals.h"
#include "trainer/residual/whiteness.h"

namespace hadynet::cli {

namespace {

namespace rs = trainer::residual;
using nlohmann::json;

std::vector<double> to_vector(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

// Everything the command computes.
struct Analysis {
  rs::ResidualData data;
  rs::HorizonMetrics horizon;
  int max_lag = rs::kDefaultMaxLag;
  std::vector<rs::Whiteness> whiteness;                       // per y channel
  std::vector<std::vector<rs::CrossCorrelation>> with_inputs;  // [c][j], u_j
  std::vector<std::vector<rs::CrossCorrelation>> with_observed;  // [c][j], y_j (j != c)
  rs::Attribution attribution;
  std::string verdict;
};

// The fitted prediction Z beta of a hypothesis, per log (0 where undefined).
rs::Segments fitted_segments(const rs::ResidualData& data, const rs::HypothesisResult& r) {
  rs::Segments out;
  for (const auto& log : data.logs) {
    const rs::Features f = rs::features(r.hypothesis, log);
    Eigen::VectorXd p = f.z * r.coef;
    p.head(f.first_valid).setZero();
    out.push_back(std::move(p));
  }
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
            {"t", r.t_stat},
            {"p_value", r.p_value},
            {"p_adjusted", r.p_adjusted},
            {"significant", r.significant},
            {"testable", r.testable}, {"plausible", r.plausible},
            {"ar_order", r.ar_order},
            {"n_train", r.n_train},
            {"n_held_out", r.n_held_out}};
  switch (h.kind) {
    case rs::EffectKind::kSensorDelay:
    case rs::EffectKind::kInputDelay:
      j["delay_steps"] = h.delay;
      break;
    case rs::EffectKind::kFriction:
      j["source"] = data.u_names[static_cast<std::size_t>(h.source)];
      break;
    case rs::EffectKind::kCrosstalk:
      j["source"] = data.y_names[static_cast<std::size_t>(h.source)];
      break;
    case rs::EffectKind::kAuxChannel:
      j["source"] = data.aux_names[static_cast<std::size_t>(h.source)];
      break;
    case rs::EffectKind::kSaturation:
      j["rail"] = h.rail;
      j["side"] = h.side > 0 ? "upper" : "lower";
      break;
    default:
      break;
  }
  return j;
}

json analysis_json(const Analysis& a, const std::string& model_path, const std::string& pb_choice) {
  const auto& d = a.data;
  json logs = json::array();
  for (const auto& log : d.logs) {
    logs.push_back({{"file", log.seq.file},
                    {"state", log.seq.state},
                    {"rows", log.seq.steps()},
                    {"pb_source", log.pb_source},
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
  return {{"model", model_path},
          {"pb", pb_choice},
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
            {"tested", att.tested},
            {"winner", w ? hypothesis_json(d, *w) : json(nullptr)},
            {"winner_family", family},
            {"ranked", ranked}}},
          {"effect_library", library}};
}

// ---- plots ----

std::string grid_header(const std::string& png, std::size_t panels, const std::string& title, int& rows) {
  const int cols = 4;
  rows = static_cast<int>((panels + cols - 1) / cols);
  return "set terminal pngcairo size 1600," + std::to_string(170 * rows + 60) + " font 'sans,8' noenhanced\n" +
         "set output " + gnuplot_quote(png) + "\nset multiplot layout " + std::to_string(rows) + "," +
         std::to_string(cols) + " title " + gnuplot_quote(title) + "\nset grid\nset key off\n";
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

std::string acf_plot(const Analysis& a, const std::string& png) {
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

std::string winner_plot(const Analysis& a, const rs::HypothesisResult& r, bool significant, const std::string& png) {
  const auto& d = a.data;
  const int c = r.hypothesis.target;
  const rs::Segments res = rs::residual_segments(d, c);
  const rs::Segments fit = fitted_segments(d, r);
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

std::string ranking_plot(const Analysis& a, const std::string& png) {
  const auto& ranked = a.attribution.ranked;
  std::vector<const rs::HypothesisResult*> top;
  for (const auto& r : ranked)
    if (r.testable) top.push_back(&r);
  std::stable_sort(top.begin(), top.end(), [](auto* x, auto* y) { return x->explained_std > y->explained_std; });
  if (top.size() > 20) top.resize(20);
  std::string s = "$b << EOD\n";
  for (std::size_t i = 0; i < top.size(); ++i) {
    std::string label = top[i]->label;
    for (char& ch : label)
      if (ch == '"') ch = '\'';
    s += std::to_string(i) + " " + num("%.6g", std::max(0.0, top[i]->explained_std)) + " " +
         (top[i]->significant ? "1" : "0") + " \"" + label + "\"\n";
  }
  s += "EOD\n";
  s += "set terminal pngcairo size 1400,700 font 'sans,9' noenhanced\nset output " + gnuplot_quote(png) + "\n";
  s += "set title " + gnuplot_quote("hypotheses by held-out explained variance (standardised units); green: significant "
                                    "(Holm-corrected p < " + num("%g", a.attribution.options.alpha) + ", above both floors)") + "\n";
  s += "set style fill solid 0.8\nset boxwidth 0.7\nset grid x\nset yrange [" + std::to_string(top.size()) +
       ":-1]\nset ytics font 'sans,8'\nset key off\n";
  s += "set arrow from " + num("%g", a.attribution.options.min_explained_std) + ",-1 to " +
       num("%g", a.attribution.options.min_explained_std) + "," + std::to_string(top.size()) + " nohead dt 2 lc rgb 'red'\n";
  s += "plot $b using (0.5*$2):1:(0.5*$2):(0.35):($3 > 0 ? 0x2ca02c : 0x999999):ytic(4) with boxxyerror lc rgb variable\n";
  return run_gnuplot(s, png);
}

// ---- Markdown ----

std::string markdown(const Analysis& a, const std::string& model_path, const std::string& pb_choice,
                     const std::vector<std::string>& pngs) {
  const auto& d = a.data;
  const auto& att = a.attribution;
  std::string m = "# Residual analysis\n\n";
  m += "Model `" + model_path + "`, " + std::to_string(d.logs.size()) + " logs, PB `" + pb_choice +
       "` (docs/residual.md explains every number).\n\n";
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
       num("%g", att.options.min_explained) + " and >= " + num("%g", att.options.min_explained_std) +
       " in standardised units. Ranked by the latter.\n\n"
       "| rank | hypothesis | effect | held-out explained (share) | standardised | train share | t | p (Holm) | significant |\n"
       "|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < att.ranked.size() && i < 20; ++i) {
    const auto& r = att.ranked[i];
    m += "| " + std::to_string(i + 1) + " | " + r.label + " | " + r.effect + " | " + num("%.3f", r.explained) + " | " +
         num("%.4f", r.explained_std) + " | " + num("%.3f", r.explained_train) + " | " + num("%.1f", r.t_stat) + " | " +
         num("%.2g", r.p_adjusted) + " | " + (r.significant ? "yes" : "no") + " |\n";
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

std::string verdict_text(const rs::Attribution& att) {
  const auto w = att.winner();
  if (!w) return "no significant effect";
  std::string v = w->effect + ": " + w->label;
  const auto family = att.winner_family();
  if (family.size() > 1) {
    v += "; also significant:";
    for (std::size_t i = 1; i < family.size(); ++i) {
      v += (i > 1 ? ", " : " ");
      v += family[i].label;
    }
  }
  return v;
}

}  // namespace

int run_residual(int argc, char** argv) {
  Options opt("residual",
              "The model's residual over logs and what it lacks (docs/residual.md): multi-step fit and RMSE per\n"
              "channel and horizon, whiteness (autocorrelation, Ljung-Box) and independence (cross-correlation\n"
              "with the inputs) of the 1-step residual, and the effect library's hypotheses (time delay,\n"
              "friction/hysteresis, drift, saturation, cross-talk, unused aux_* channels) fitted on the first part\n"
              "of each log and tested on the rest. Prints the winner with its parameters, or 'no significant\n"
              "effect'. Works on any (u, y) logs the model's channels fit.",
              "MODEL LOG|DIR... [options]");
  opt.value("pb", "PB",
            "auto (the state's PB if the model knows it, else adapted), state, adapt, zero, a state, or values", "auto");
  opt.value("horizon", "N", "multi-step horizon (default: the model's N_train)");
  opt.value("max-lag", "L", "correlation lags 1..L (whiteness) and -L..L (independence)",
            std::to_string(rs::kDefaultMaxLag));
  opt.value("max-delay", "D", "delays tested: 1..D steps", "5");
  opt.value("train-fraction", "F", "part of each log (from its start) the hypotheses are fitted on", "0.6");
  opt.value("alpha", "A", "family-wise error rate of the Holm-corrected tests", "0.01");
  opt.value("min-explained", "S", "floor: share of the held-out residual variance an effect must explain", "0.1");
  opt.value("min-explained-std", "V",
            "floor: held-out explained variance in standardised units (drop of the channel's 1-step loss)", "0.05");
  opt.flag("all-sources", "cross-talk sources from every observed group (default: the target's group)");
  opt.value("report", "DIR", "write DIR/REPORT.md with PNG plots (gnuplot) and DIR/residual.json");
  opt.value("json", "FILE", "write every number as JSON");
  opt.flag("fix", "add the winning effect (sensor delay: time alignment; cross-talk: removal; drift: a bias state;\n"
                  "saturation: clipping; friction: hysteresis inputs; aux channel: an observed channel), fine-tune\n"
                  "on the first --train-fraction of each log and report before/after on the rest");
  opt.value("out", "FILE", "with --fix: write the augmented model (only when something was fixed)");
  opt.value("fix-epochs", "N", "with --fix: fine-tuning epochs", "20");
  opt.value("fix-lr", "X", "with --fix: Adam learning rate", "0.001");
  opt.value("fix-seed", "N", "with --fix: seed of the window order", "1");
  opt.flag("no-control", "with --fix: skip the fine-tune-only comparison");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (opt.positional().size() < 2) {
    std::fprintf(stderr, "hadynet residual: give MODEL and logs (see --help)\n");
    return 2;
  }
  const auto max_lag = opt.get_int("max-lag", 1, 1000);
  const auto max_delay = opt.get_int("max-delay", 1, 100);
  const auto fraction = opt.get_double("train-fraction", 0.1, 0.9);
  const auto alpha = opt.get_double("alpha", 1e-12, 0.5);
  const auto min_share = opt.get_double("min-explained", 0.0, 1.0);
  const auto min_std = opt.get_double("min-explained-std", 0.0, 1e6);
  std::optional<long long> horizon;
  if (opt.has("horizon")) {
    horizon = opt.get_int("horizon", 1, 1000);
    if (!horizon) return 2;
  }
  if (!max_lag || !max_delay || !fraction || !alpha || !min_share || !min_std) return 2;
  const auto fix_epochs = opt.get_int("fix-epochs", 1, 100000);
  const auto fix_lr = opt.get_double("fix-lr", 1e-12, 10.0);
  const auto fix_seed = opt.get_int("fix-seed", 0, (1ll << 62));
  if (!fix_epochs || !fix_lr || !fix_seed) return 2;
  if (opt.has("out") && !opt.has("fix")) {
    std::fprintf(stderr, "hadynet residual: --out needs --fix\n");
    return 2;
  }

  try {
    const std::string model_path = opt.positional().front();
    const trainer::HadynetModel model = trainer::load_model(model_path);
    const std::vector<std::string> args(opt.positional().begin() + 1, opt.positional().end());
    std::vector<rs::LogInput> inputs;
    for (const auto& path : trainer::expand_log_paths(args)) inputs.push_back({datalog::read_log(path), path});

    Analysis a;
    a.max_lag = static_cast<int>(*max_lag);
    const std::string pb_choice = opt.get("pb");
    a.data = rs::compute_residuals(model, inputs, pb_choice);
    a.horizon = rs::horizon_metrics(model, a.data, horizon ? static_cast<int>(*horizon) : model.train_steps);
    if (!a.horizon.rmse.allFinite()) {
      // Never a table of NaN with "no significant effect" under it.
      throw std::runtime_error(model_path + ": the model's prediction is not finite on these logs (float32 "
                               "overflow in the network); no residual can be analysed");
    }
    const auto& d = a.data;
    const std::size_t ny = d.y_names.size(), nu = d.u_names.size();
    a.with_inputs.assign(ny, {});
    a.with_observed.assign(ny, std::vector<rs::CrossCorrelation>(ny));
    std::vector<rs::Segments> inputs_seg, observed_seg;
    for (std::size_t j = 0; j < nu; ++j) inputs_seg.push_back(rs::input_segments(d, static_cast<int>(j)));
    for (std::size_t j = 0; j < ny; ++j) observed_seg.push_back(rs::observed_segments(d, static_cast<int>(j)));
    for (std::size_t c = 0; c < ny; ++c) {
      const rs::Segments r = rs::residual_segments(d, static_cast<int>(c));
      a.whiteness.push_back(rs::whiteness(r, a.max_lag));
      for (std::size_t j = 0; j < nu; ++j) a.with_inputs[c].push_back(rs::cross_correlate(r, inputs_seg[j], a.max_lag));
      for (std::size_t j = 0; j < ny; ++j)
        if (j != c) a.with_observed[c][j] = rs::cross_correlate(r, observed_seg[j], a.max_lag);
    }
    rs::LibraryOptions lib;
    lib.max_delay = static_cast<int>(*max_delay);
    lib.crosstalk_same_group = !opt.has("all-sources");
    rs::AttributionOptions ao;
    ao.train_fraction = *fraction;
    ao.alpha = *alpha;
    ao.min_explained = *min_share;
    ao.min_explained_std = *min_std;
    a.attribution = rs::attribute(d, rs::enumerate_hypotheses(d, lib), ao);
    a.verdict = verdict_text(a.attribution);

    // Console summary.
    std::printf("%zu logs, %zu channels, PB %s; multi-step fit over %ld window starts\n", d.logs.size(), ny,
                pb_choice.c_str(), a.horizon.samples);
    std::printf("%-10s %9s %9s %11s %11s %9s %6s\n", "channel", "fit h=1", "RMSE h=1",
                ("fit h=" + std::to_string(a.horizon.horizon)).c_str(),
                ("RMSE h=" + std::to_string(a.horizon.horizon)).c_str(), "LB p", "white");
    for (std::size_t c = 0; c < ny; ++c) {
      const auto r = static_cast<Eigen::Index>(c);
      const Eigen::Index H = a.horizon.horizon - 1;
      std::printf("%-10s %8.1f%% %9.4g %10.1f%% %11.4g %9.2g %6s\n", d.y_names[c].c_str(), a.horizon.fit(r, 0),
                  a.horizon.rmse(r, 0), a.horizon.fit(r, H), a.horizon.rmse(r, H), a.whiteness[c].ljung_box.p_value,
                  a.whiteness[c].white() ? "yes" : "no");
    }
    std::printf("\n%ld hypotheses tested; top of the ranking:\n", a.attribution.tested);
    for (std::size_t i = 0; i < a.attribution.ranked.size() && i < 10; ++i) {
      const auto& r = a.attribution.ranked[i];
      std::printf("  %c %-62s explained %6.3f (std %.4f)  p(Holm) %.2g\n", r.significant ? '*' : ' ', r.label.c_str(),
                  r.explained, r.explained_std, r.p_adjusted);
    }
    std::printf("\nverdict: %s\n", a.verdict.c_str());

    json j = analysis_json(a, model_path, pb_choice);
    rs::FixOptions fo;
    fo.train_fraction = *fraction;
    fo.epochs = static_cast<int>(*fix_epochs);
    fo.lr = *fix_lr;
    fo.seed = static_cast<std::uint64_t>(*fix_seed);
    fo.control = !opt.has("no-control");
    std::optional<rs::FixResult> fixed;
    std::string written;
    if (opt.has("fix")) {
      fixed = rs::fix(model, inputs, d, a.attribution, fo);
      std::printf("\nfix: %s%s\n", fixed->status.c_str(),
                  fixed->augmentation ? (": " + fixed->augmentation->description).c_str() : "");
      const rs::HeldOutError& e = fixed->changed ? fixed->after : fixed->before;
      std::printf("held-out 1-step RMSE (%ld rows)   %-10s %11s %11s %11s   LB p before/after\n", fixed->before.samples,
                  "channel", "before", "fine-tune", "after");
      for (std::size_t c = 0; c < e.channels.size(); ++c) {
        const auto i = static_cast<Eigen::Index>(c);
        const bool old = c < fixed->before.channels.size();
        std::printf("                                  %-10s %11.4g %11.4g %11.4g   %.2g / %.2g\n", e.channels[c].c_str(),
                    old ? fixed->before.rmse(i) : NAN, fixed->control && old ? fixed->control->rmse(i) : NAN,
                    fixed->changed ? fixed->after.rmse(i) : NAN,
                    old ? fixed->before.whiteness[c].ljung_box.p_value : NAN,
                    fixed->changed ? fixed->after.whiteness[c].ljung_box.p_value : NAN);
      }
      if (fixed->changed) std::printf("verdict after: %s\n", fixed->after.verdict.c_str());
      if (fixed->changed && opt.has("out")) {
        written = opt.get("out");
        trainer::save_model(written, fixed->model);
        std::fprintf(stderr, "wrote %s\n", written.c_str());
      } else if (opt.has("out")) {
        std::fprintf(stderr, "nothing fixed: %s not written\n", opt.get("out").c_str());
      }
      j["fix"] = fix_json(*fixed, fo);
      if (!written.empty()) j["fix"]["model"] = written;
    }
    auto write_json = [&](const std::string& path) {
      std::ofstream out(path);
      if (!out) throw std::runtime_error(path + ": cannot write");
      out << j.dump(1) << '\n';
      if (!out) throw std::runtime_error(path + ": write failed");
      std::fprintf(stderr, "wrote %s\n", path.c_str());
    };
    if (opt.has("json")) write_json(opt.get("json"));
    if (opt.has("report")) {
      const std::filesystem::path dir = opt.get("report");
      std::filesystem::create_directories(dir);
      write_json((dir / "residual.json").string());
      std::vector<std::string> pngs;
      auto plot = [&](const std::string& name, const std::string& err) {
        if (!err.empty()) throw std::runtime_error(err);
        pngs.push_back(name);
      };
      plot("residuals.png", residual_trace_plot(d, (dir / "residuals.png").string()));
      plot("autocorrelation.png", acf_plot(a, (dir / "autocorrelation.png").string()));
      const auto w = a.attribution.winner();
      const rs::HypothesisResult* best = nullptr;
      for (const auto& r : a.attribution.ranked)
        if (r.testable && (best == nullptr || r.explained_std > best->explained_std)) best = &r;
      if (w || best != nullptr)
        plot("winner.png", winner_plot(a, w ? *w : *best, w.has_value(), (dir / "winner.png").string()));
      plot("ranking.png", ranking_plot(a, (dir / "ranking.png").string()));
      const std::string md_path = (dir / "REPORT.md").string();
      std::ofstream md(md_path);
      if (!md) throw std::runtime_error(md_path + ": cannot write");
      md << markdown(a, model_path, pb_choice, pngs);
      std::string fix_png;
      if (fixed && fixed->changed) {
        plot("fix.png", fix_plot(*fixed, (dir / "fix.png").string()));
        pngs.pop_back();  // shown in the Fix section
        fix_png = "fix.png";
      }
      if (fixed) md << fix_markdown(*fixed, fo, written, fix_png);
      std::fprintf(stderr, "wrote %s\n", md_path.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet residual: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
