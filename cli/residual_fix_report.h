// The --fix part of `hadynet residual`'s outputs (docs/residual.md, "--fix").
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "trainer/residual/augment.h"

namespace hadynet::cli {

// The "fix" object of the JSON: status, augmentation, the fixed model's
// sensor model, and before / fine-tune only / after per channel.
nlohmann::json fix_json(const trainer::residual::FixResult& f, const trainer::residual::FixOptions& o);

// The "Fix" section of REPORT.md; `out` is the written model ("" if none),
// `png` the plot's file name in the report folder ("" if none).
std::string fix_markdown(const trainer::residual::FixResult& f, const trainer::residual::FixOptions& o,
                         const std::string& out, const std::string& png);

// One sentence on a wider plan tested after the confirmation
// (FixResult::extensions): the channels it adds, the test and whether it was
// applied. For stdout and REPORT.md.
std::string extension_sentence(const trainer::residual::FixResult::Extension& e);

// One sentence on a drift probe (FixResult::drift_probes): its rate, its
// test and whether it became a candidate.
std::string drift_probe_sentence(const trainer::residual::DriftProbe& p);

// One sentence on the simpler account tried after the confirmation
// (FixResult::simpler): its channels, its test against the reference, the
// confirmed change's gain over it when tested, and whether it was applied.
// For stdout and REPORT.md.
std::string simpler_sentence(const trainer::residual::FixResult::SimplerAccount& s, const std::string& reference);

// One sentence on the richer account tried after the confirmation
// (FixResult::richer): its channels, its test against the reference (and on
// its own channels), its gain over the confirmed change when tested, and
// whether it was applied. For stdout and REPORT.md.
// The rivals tested beside the selection's choice, at Holm's levels.
std::string rivals_sentence(const trainer::residual::FixResult::Rivals& r, const std::string& reference);
std::string richer_sentence(const trainer::residual::FixResult::RicherAccount& r, const std::string& reference);

// Whether a plan other than the decision's was applied after the
// confirmation (the simpler or richer account, or a wider plan): the before/after are
// then the plan applied last.
bool replaced_after_decision(const trainer::residual::FixResult& f);

// fix.png: each channel's held-out RMSE after the fix and after fine-tuning
// alone, relative to before. Returns "" on success (or nothing to plot), else
// a message (gnuplot missing or failed).
std::string fix_plot(const trainer::residual::FixResult& f, const std::string& png);

}  // namespace hadynet::cli
