#include "host-sim/plant/hand_spec.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "host-sim/plant/rng.h"

namespace hadynet::plant {

namespace {
struct ObjectNameEntry {
  ObjectKind kind;
  std::string_view name;
};
constexpr ObjectNameEntry kObjectNames[] = {
    {ObjectKind::kNone, "None"},         {ObjectKind::kHammer, "Hammer"},
    {ObjectKind::kHammerSoft, "Hammer-S"}, {ObjectKind::kCylinder, "Cylinder"},
    {ObjectKind::kGripper, "Gripper"},   {ObjectKind::kBall, "Ball"},
    {ObjectKind::kCylinderLarge, "Cylinder-L"},
};

bool parse_double(std::string_view text, double& out) {
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, out);
  return ec == std::errc() && ptr == end && std::isfinite(out);
}
}  // namespace

std::string_view object_name(ObjectKind kind) {
  for (const auto& e : kObjectNames)
    if (e.kind == kind) return e.name;
  return "?";
}

std::string object_list() {
  std::string out;
  for (const auto& e : kObjectNames) out += (out.empty() ? "" : ", ") + std::string(e.name);
  return out;
}

std::optional<ObjectKind> parse_object(std::string_view name) {
  for (const auto& e : kObjectNames) {
    if (e.name.size() != name.size()) continue;
    bool same = true;  // case-insensitive
    for (std::size_t i = 0; i < name.size(); ++i)
      if (std::tolower(static_cast<unsigned char>(e.name[i])) != std::tolower(static_cast<unsigned char>(name[i])))
        same = false;
    if (same) return e.kind;
  }
  return std::nullopt;
}

Wear wear_from_level(double level) {
  Wear w;
  w.level = level;
  w.spring_stiffness_scale = 1.0 - 0.15 * level;
  w.tendon_elongation_mm = 2.0 * level;
  w.servo_stiffness_scale = 1.0 / (1.0 + 0.5 * level);
  return w;
}

bool Effects::any() const {
  return tendon_friction_N > 0 || loadcell_delay_steps > 0 || loadcell_drift_per_Ns > 0 ||
         loadcell_drift_walk_N > 0 || loadcell_rail_N > 0 || loadcell_crosstalk > 0 ||
         tension_leak > 0 || command_delay_steps > 0 || loadcell_curve_exponent != 1.0;
}

std::string Effects::describe() const {
  std::string out;
  char buf[96];
  auto add = [&](const char* text) {
    if (!out.empty()) out += ',';
    out += text;
  };
  if (tendon_friction_N > 0) { std::snprintf(buf, sizeof buf, "friction=%g", tendon_friction_N); add(buf); }
  if (loadcell_delay_steps > 0) { std::snprintf(buf, sizeof buf, "sensor-delay=%d", loadcell_delay_steps); add(buf); }
  if (loadcell_drift_per_Ns > 0 || loadcell_drift_walk_N > 0) {
    std::snprintf(buf, sizeof buf, "drift=%g/%g", loadcell_drift_per_Ns, loadcell_drift_walk_N);
    add(buf);
  }
  if (loadcell_rail_N > 0) { std::snprintf(buf, sizeof buf, "saturation=%g", loadcell_rail_N); add(buf); }
  if (loadcell_crosstalk > 0) { std::snprintf(buf, sizeof buf, "crosstalk=%g", loadcell_crosstalk); add(buf); }
  if (tension_leak > 0) { std::snprintf(buf, sizeof buf, "tension-leak=%g", tension_leak); add(buf); }
  if (command_delay_steps > 0) { std::snprintf(buf, sizeof buf, "input-delay=%d", command_delay_steps); add(buf); }
  if (loadcell_curve_exponent != 1.0) {
    std::snprintf(buf, sizeof buf, "sensor-curve=%g", loadcell_curve_exponent);
    add(buf);
  }
  return out.empty() ? "none" : out;
}

std::string apply_effect_arg(std::string_view arg, Effects& e) {
  const auto eq = arg.find('=');
  const std::string_view name = arg.substr(0, eq);
  const bool has_value = eq != std::string_view::npos;
  double value = 0;
  if (has_value && !parse_double(arg.substr(eq + 1), value))
    return "effect '" + std::string(arg) + "': expected NAME=NUMBER";
  if (has_value && value < 0) return "effect '" + std::string(arg) + "': value must be >= 0";
  if (name == "friction") {
    e.tendon_friction_N = has_value ? value : 4.0;
  } else if (name == "sensor-delay") {
    if (has_value && (value > 20 || value != std::floor(value)))
      return "effect 'sensor-delay': expected a whole number of steps in 0..20";
    e.loadcell_delay_steps = has_value ? static_cast<int>(value) : 2;
  } else if (name == "drift") {
    e.loadcell_drift_per_Ns = has_value ? value : 0.004;
    e.loadcell_drift_walk_N = 0.01;
  } else if (name == "saturation") {
    e.loadcell_rail_N = has_value ? value : 3.0;
  } else if (name == "crosstalk") {
    e.loadcell_crosstalk = has_value ? value : 0.35;
    if (e.loadcell_crosstalk > 1) return "effect 'crosstalk': expected a fraction in 0..1";
  } else if (name == "tension-leak") {
    e.tension_leak = has_value ? value : 0.05;
    if (e.tension_leak > 1) return "effect 'tension-leak': expected a fraction in 0..1";
  } else if (name == "input-delay") {
    if (has_value && (value > 20 || value != std::floor(value)))
      return "effect 'input-delay': expected a whole number of steps in 0..20";
    e.command_delay_steps = has_value ? static_cast<int>(value) : 2;
  } else if (name == "sensor-curve") {
    const double exponent = has_value ? value : 0.85;
    if (!(exponent > 0.2 && exponent <= 5)) return "effect 'sensor-curve': expected an exponent in (0.2, 5]";
    e.loadcell_curve_exponent = exponent;
  } else {
    return "unknown effect '" + std::string(name) +
           "' (expected friction, sensor-delay, drift, saturation, crosstalk, tension-leak, input-delay or "
           "sensor-curve)";
  }
  return "";
}

std::string effect_arg_help(const std::string& indent) {
  return "switch on an effect the model may lack: friction[=N], sensor-delay[=steps], drift[=N/(N s)],\n" + indent +
         "saturation[=rail N], crosstalk[=fraction], tension-leak[=fraction],\n" + indent +
         "input-delay[=steps], sensor-curve[=exponent: loadcells read 50 N (F / 50 N)^exponent]";
}

std::array<double, kMuscles> encoder_offsets_for(int init_id, std::uint64_t seed) {
  Rng rng(derive_seed(seed, 0x1417u, static_cast<std::uint64_t>(init_id)));
  std::array<double, kMuscles> out{};
  for (auto& o : out) o = rng.uniform(-1.5, 1.5);
  return out;
}

}  // namespace hadynet::plant
