// Command channels computed from other command channels, so that a model
// can use them without them being logged (docs/residual.md, friction --fix).
// A model's u channel named
//   sign_<c>   is sign(u_c(t))                         (-1, 0 or +1)
//   hyst_<c>   is the hysteresis state of u_c at t:     the sign of the last
//              non-zero u_c(s), s <= t; 0 before the first one
//   dsign_<c>  is sign(u_c(t) - u_c(t-1)), 0 in the first row: the direction
//              an absolute command (a position or voltage set point) moves
//   dhyst_<c>  is the sign of the last non-zero change of u_c up to t; 0
//              before the first
//   lag<d>_<c> is u_c(t - d), d = 1..kMaxCommandLag steps; 0 in the first d
//              rows (no command before the log): the command as a plant with
//              d steps of dead time acts on it
// for a command column <c> of the log: sign_/hyst_ for incremental commands
// (a command is a motion), dsign_/dhyst_ for absolute ones (a command is a
// level; docs/residual.md, "Absolute inputs"), lag<d>_ for either (input
// dead time; docs/residual.md, "Input dead time"). All are causal: row t uses
// rows <= t only, so a host (or the firmware) can compute them from the
// commands it has sent. log_sequence() computes them when a log lacks the
// column.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "datalog/log_table.h"
#include "firmware/core/model_contract.h"

namespace hadynet::trainer {

enum class DerivedKind { kSign, kHysteresis, kChangeSign, kChangeHysteresis, kLag };

// The longest dead time a lag<d>_ input may state (steps): the firmware's.
inline constexpr int kMaxCommandLag = firmware::kMaxDerivedLag;

struct DerivedInput {
  DerivedKind kind;
  std::string base;  // the command column it is computed from, e.g. "u0"
  int lag = 0;       // steps, 1..kMaxCommandLag for kLag; 0 for the others
};

// The derivation a channel name states ("sign_u0", "hyst_u0", "dsign_u0",
// "dhyst_u0", "lag2_u0"); none for any other name.
std::optional<DerivedInput> parse_derived_input(const std::string& name);
std::string derived_input_name(const DerivedInput& d);

// The derived values of a base command series, row by row (as above); `lag`
// (steps) is read for kLag only.
std::vector<double> derived_input_values(DerivedKind kind, const std::vector<double>& base, int lag = 0);

// The channel's value in every row of `table`; none if `name` is not a
// derived name or the table has no column `base`.
std::optional<std::vector<double>> derived_input_column(const datalog::LogTable& table, const std::string& name);

}  // namespace hadynet::trainer
