#include "trainer/residual/drift_probe.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "trainer/log_dataset.h"

namespace hadynet::trainer::residual {

Augmentation group_drift_plan(const std::vector<std::string>& channels, double period_s, double rate) {
  Augmentation a;
  a.kind = EffectKind::kDriftLoad;
  a.effect = effect_info(a.kind).name;
  a.group_extension = true;  // planned on its whole group (never a family alone: is_family_alone)
  auto& change = a.change.emplace<BiasState>();
  change.period_s = period_s;
  change.common_rate = true;
  for (const auto& name : channels) change.drifts.push_back({name, true, rate});
  a.channels = channels;
  a.found_on = channels;
  a.description = "a bias state growing with the accumulated load on " + join(channels) +
                  " (the drift probe: every channel of the group, one rate for the group), removed from the data and "
                  "added to the prediction";
  return a;
}

double start_rate(const ResidualData& data, const std::vector<std::string>& channels) {
  double scale = 0, load = 0;
  long n_scale = 0, n_load = 0;
  for (const auto& name : channels) {
    const auto it = std::find(data.y_names.begin(), data.y_names.end(), name);
    if (it == data.y_names.end()) throw std::logic_error("drift probe: " + name + " is not an analysed channel");
    const auto c = static_cast<Eigen::Index>(it - data.y_names.begin());
    scale += data.y_scale(c);
    ++n_scale;
    for (const auto& log : data.logs) {
      load += log.seq.y.row(c).cwiseAbs().sum() * log.dt_s;
      ++n_load;
    }
  }
  if (n_scale == 0 || n_load == 0) return 0;
  load /= static_cast<double>(n_load);
  scale /= static_cast<double>(n_scale);
  return load > 0 && std::isfinite(load) ? 0.25 * scale / load : 0.0;
}

std::vector<DriftProbe> probe_drifts(const HadynetModel& model, const ResidualData& data, const DriftProbeRows& rows,
                                     double alpha) {
  std::vector<DriftProbe> probes;
  if (data.logs.empty()) return probes;
  const double period_s = data.logs.front().dt_s;
  for (const auto& log : data.logs)
    if (log.dt_s != period_s || !(period_s > 0)) return probes;  // a drift needs one period (drift::plan says why)
  const auto drifting = [&](const std::string& name) {
    return std::any_of(model.sensor.drifts.begin(), model.sensor.drifts.end(),
                       [&](const SensorDrift& d) { return d.channel == name; });
  };
  for (const auto& name : model.layout.y_names) {
    const std::string group = channel_group(name);
    if (std::any_of(probes.begin(), probes.end(), [&](const DriftProbe& p) { return p.group == group; })) continue;
    DriftProbe p;
    p.group = group;
    for (const auto& other : model.layout.y_names)
      if (channel_group(other) == group && !drifting(other)) p.channels.push_back(other);
    if (p.channels.empty()) continue;
    probes.push_back(std::move(p));
  }
  // The family of Holm's correction: the groups whose re-estimated rate is
  // positive. The rate is fitted on rows the test does not judge, so which
  // groups are tested does not depend on the judged rows (as the screen's
  // fit and test, attribution.h).
  std::vector<double> p_values;
  std::vector<std::size_t> tested;
  for (std::size_t i = 0; i < probes.size(); ++i) {
    DriftProbe& p = probes[i];
    p.start_rate = start_rate(data, p.channels);
    if (!(p.start_rate > 0)) continue;
    const Augmentation plan = rows.refined(group_drift_plan(p.channels, period_s, p.start_rate));
    const auto& drifts = std::get<BiasState>(plan.change).drifts;
    p.rate = drifts.empty() ? 0.0 : drifts.front().rate;
    if (!(p.rate > 0)) continue;
    p.gain = diebold_mariano(rows.loss(model.sensor, p.channels), rows.loss(sensor_after(model.sensor, plan), p.channels));
    p_values.push_back(p.gain.p_value);
    tested.push_back(i);
  }
  const std::vector<double> adjusted = holm_adjust(p_values);
  for (std::size_t k = 0; k < tested.size(); ++k) {
    DriftProbe& p = probes[tested[k]];
    p.p_adjusted = adjusted[k];
    p.candidate = p.gain.mean > 0 && p.p_adjusted < alpha;
  }
  return probes;
}

std::vector<const DriftProbe*> candidate_drift_probes(const std::vector<DriftProbe>& probes) {
  std::vector<const DriftProbe*> out;
  for (const DriftProbe& p : probes)
    if (p.candidate) out.push_back(&p);
  std::stable_sort(out.begin(), out.end(),
                   [](const DriftProbe* a, const DriftProbe* b) { return a->p_adjusted < b->p_adjusted; });
  return out;
}

}  // namespace hadynet::trainer::residual
