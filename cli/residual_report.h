// The analysis part of `hadynet residual`'s outputs (docs/residual.md): the
// JSON with every number, the Markdown report and its plots (gnuplot). The
// --fix part is cli/residual_fix_report.h.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "trainer/residual/analysis.h"
#include "trainer/residual/augment.h"

namespace hadynet::cli {

// DIR/REPORT.md with its plots (PNG, gnuplot): the analysis, then the Fix
// section when `fixed` is given (`written`: the model file written, "" if
// none). Throws std::runtime_error when a file cannot be written or gnuplot
// fails.
void write_report(const std::filesystem::path& dir, const trainer::residual::Analysis& a,
                  const std::string& model_path, const std::string& pb_choice,
                  const trainer::residual::FixResult* fixed, const trainer::residual::FixOptions& fix_options,
                  const std::string& written);

// Every number of the analysis; `pb_choice` as given on the command line.
nlohmann::json analysis_json(const trainer::residual::Analysis& a, const std::string& model_path,
                             const std::string& pb_choice);

// REPORT.md up to (not including) the Fix section; `pngs` are the plots'
// file names in the report folder, shown in order.
std::string markdown(const trainer::residual::Analysis& a, const std::string& model_path,
                     const std::string& pb_choice, const std::vector<std::string>& pngs);

// The analysis plots (PNG through gnuplot). Each returns "" on success, else
// a message (gnuplot missing or failed).
// residuals.png: each channel's 1-step residual, logs one after another.
std::string residual_trace_plot(const trainer::residual::ResidualData& d, const std::string& png);
// autocorrelation.png: each channel's residual ACF with the 99 % bounds.
std::string acf_plot(const trainer::residual::Analysis& a, const std::string& png);
// winner.png: the shown hypothesis' cross-correlation and fitted effect
// (`significant` false labels it "best (not significant)").
std::string winner_plot(const trainer::residual::Analysis& a, const trainer::residual::HypothesisResult& r,
                        bool significant, const std::string& png);
// ranking.png: the top 20 testable hypotheses by standardised explained variance.
std::string ranking_plot(const trainer::residual::Analysis& a, const std::string& png);

}  // namespace hadynet::cli
