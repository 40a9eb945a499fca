#include "trainer/derived_inputs.h"

#include <array>
#include <charconv>
#include <utility>

namespace hadynet::trainer {

namespace {

// Prefix of each kind's channel name, in DerivedKind order.
constexpr std::array<std::pair<const char*, DerivedKind>, 4> kPrefixes = {{{"sign_", DerivedKind::kSign},
                                                                           {"hyst_", DerivedKind::kHysteresis},
                                                                           {"dsign_", DerivedKind::kChangeSign},
                                                                           {"dhyst_", DerivedKind::kChangeHysteresis}}};

double sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

// "lag<d>_<base>" with d a decimal 1..kMaxCommandLag without leading zeros.
std::optional<DerivedInput> parse_lag(const std::string& name) {
  if (name.compare(0, 3, "lag") != 0) return std::nullopt;
  const auto underscore = name.find('_', 3);
  if (underscore == std::string::npos || underscore == 3 || underscore + 1 == name.size()) return std::nullopt;
  if (name[3] == '0') return std::nullopt;
  int lag = 0;
  const char* end = name.data() + underscore;
  const auto [p, ec] = std::from_chars(name.data() + 3, end, lag);
  if (ec != std::errc{} || p != end || lag < 1 || lag > kMaxCommandLag) return std::nullopt;
  return DerivedInput{DerivedKind::kLag, name.substr(underscore + 1), lag};
}

}  // namespace

std::optional<DerivedInput> parse_derived_input(const std::string& name) {
  for (const auto& [prefix, kind] : kPrefixes) {
    const std::string p = prefix;
    if (name.size() > p.size() && name.compare(0, p.size(), p) == 0) return DerivedInput{kind, name.substr(p.size())};
  }
  return parse_lag(name);
}

std::string derived_input_name(const DerivedInput& d) {
  if (d.kind == DerivedKind::kLag) return "lag" + std::to_string(d.lag) + "_" + d.base;
  return kPrefixes[static_cast<std::size_t>(d.kind)].first + d.base;
}

std::vector<double> derived_input_values(DerivedKind kind, const std::vector<double>& base, int lag) {
  if (kind == DerivedKind::kLag) {
    std::vector<double> out(base.size(), 0.0);
    for (std::size_t t = static_cast<std::size_t>(lag); t < base.size(); ++t) out[t] = base[t - static_cast<std::size_t>(lag)];
    return out;
  }
  const bool of_change = kind == DerivedKind::kChangeSign || kind == DerivedKind::kChangeHysteresis;
  const bool hysteresis = kind == DerivedKind::kHysteresis || kind == DerivedKind::kChangeHysteresis;
  std::vector<double> out(base.size());
  double state = 0;
  for (std::size_t t = 0; t < base.size(); ++t) {
    const double s = of_change ? (t == 0 ? 0.0 : sign(base[t] - base[t - 1])) : sign(base[t]);
    if (s != 0) state = s;
    out[t] = hysteresis ? state : s;
  }
  return out;
}

std::optional<std::vector<double>> derived_input_column(const datalog::LogTable& table, const std::string& name) {
  const auto d = parse_derived_input(name);
  if (!d) return std::nullopt;
  const auto base = table.column_index(d->base);
  if (!base) return std::nullopt;
  std::vector<double> values(table.rows());
  for (std::size_t t = 0; t < table.rows(); ++t) values[t] = table.at(t, *base);
  return derived_input_values(d->kind, values, d->lag);
}

}  // namespace hadynet::trainer
