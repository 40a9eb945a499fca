#include "trainer/derived_inputs.h"

namespace hadynet::trainer {

namespace {

constexpr const char* kSignPrefix = "sign_";
constexpr const char* kHystPrefix = "hyst_";

double sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

}  // namespace

std::optional<DerivedInput> parse_derived_input(const std::string& name) {
  for (const auto& [prefix, kind] : {std::pair{kSignPrefix, DerivedKind::kSign}, {kHystPrefix, DerivedKind::kHysteresis}}) {
    const std::string p = prefix;
    if (name.size() > p.size() && name.compare(0, p.size(), p) == 0) return DerivedInput{kind, name.substr(p.size())};
  }
  return std::nullopt;
}

std::string derived_input_name(const DerivedInput& d) {
  return (d.kind == DerivedKind::kSign ? kSignPrefix : kHystPrefix) + d.base;
}

std::optional<std::vector<double>> derived_input_column(const datalog::LogTable& table, const std::string& name) {
  const auto d = parse_derived_input(name);
  if (!d) return std::nullopt;
  const auto base = table.column_index(d->base);
  if (!base) return std::nullopt;
  std::vector<double> out(table.rows());
  double state = 0;
  for (std::size_t t = 0; t < table.rows(); ++t) {
    const double s = sign(table.at(t, *base));
    if (s != 0) state = s;
    out[t] = d->kind == DerivedKind::kSign ? s : state;
  }
  return out;
}

}  // namespace hadynet::trainer
