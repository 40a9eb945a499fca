#include "host-sim/plant/disturbance.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <vector>

namespace hadynet::plant {

namespace {

constexpr double kMaxSteps = 1e6;  // bound on integer fields (steps, strikes)

std::string number_text(double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest text that reads back exactly
  return ec == std::errc() ? std::string(buf, end) : std::string("nan");
}

std::string vector_text(const std::array<double, 3>& v) {
  return number_text(v[0]) + "," + number_text(v[1]) + "," + number_text(v[2]);
}

bool all_zero(const std::array<double, 3>& v) { return v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0; }

bool parse_number(std::string_view text, double& out) {
  if (text.empty()) return false;
  if (text.front() == '+') text.remove_prefix(1);  // from_chars rejects a leading '+'
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, out);
  return ec == std::errc() && ptr == end && std::isfinite(out);
}

struct Field {
  std::string name;
  std::vector<std::string_view> values;
};

// "a=1,b=2,3,4" -> {a: [1]}, {b: [2, 3, 4]}: a token without '=' continues
// the previous field's value list.
std::string split_fields(std::string_view text, std::vector<Field>& fields) {
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    const std::string_view token = text.substr(pos, comma - pos);
    pos = comma + 1;
    if (token.empty()) return "empty field in '" + std::string(text) + "'";
    const auto eq = token.find('=');
    if (eq == std::string_view::npos) {
      if (fields.empty()) return "expected FIELD=VALUE, got '" + std::string(token) + "'";
      fields.back().values.push_back(token);
    } else {
      if (eq == 0) return "missing field name before '=' in '" + std::string(token) + "'";
      fields.push_back({std::string(token.substr(0, eq)), {token.substr(eq + 1)}});
    }
  }
  return "";
}

std::string field_error(const Field& f, const std::string& what) { return "disturbance field '" + f.name + "': " + what; }

std::string read_vector(const Field& f, std::array<double, 3>& out) {
  if (f.values.size() != 3)
    return field_error(f, "expected 3 comma-separated numbers (X,Y,Z), got " + std::to_string(f.values.size()));
  for (int i = 0; i < 3; ++i)
    if (!parse_number(f.values[i], out[i])) return field_error(f, "'" + std::string(f.values[i]) + "' is not a finite number");
  return "";
}

std::string read_scalar(const Field& f, double& out) {
  if (f.values.size() != 1) return field_error(f, "expected one number, got " + std::to_string(f.values.size()));
  if (!parse_number(f.values[0], out)) return field_error(f, "'" + std::string(f.values[0]) + "' is not a finite number");
  return "";
}

std::string read_count(const Field& f, int min_value, int& out) {
  double v = 0;
  if (auto e = read_scalar(f, v); !e.empty()) return e;
  if (v != std::floor(v) || v < min_value || v > kMaxSteps)
    return field_error(f, "expected a whole number >= " + std::to_string(min_value) + ", got '" +
                              std::string(f.values[0]) + "'");
  out = static_cast<int>(v);
  return "";
}

}  // namespace

bool Wrench::is_zero() const { return all_zero(force_N) && all_zero(torque_Nm); }

bool Disturbance::striking(int step) const {
  if (!enabled || step < start_step || period_steps < 1) return false;
  return (step - start_step) % period_steps < duration_steps;
}

Wrench Disturbance::at(int step) const {
  Wrench w;
  if (!enabled || step < start_step) return w;
  const int since = step - start_step;
  if (striking(step)) {
    const int strike = since / period_steps;
    const double amplitude = ramp_strikes > 0 ? std::min(1.0, (strike + 1.0) / ramp_strikes) : 1.0;
    for (int i = 0; i < 3; ++i) {
      w.force_N[i] = amplitude * force_N[i];
      w.torque_Nm[i] = amplitude * torque_Nm[i];
    }
  }
  if (!all_zero(drift_N_per_step)) {
    std::array<double, 3> steady{};
    double norm2 = 0;
    for (int i = 0; i < 3; ++i) {
      steady[i] = drift_N_per_step[i] * (since + 1);
      norm2 += steady[i] * steady[i];
    }
    const double norm = std::sqrt(norm2);
    const double scale = drift_max_N > 0 && norm > drift_max_N ? drift_max_N / norm : 1.0;
    for (int i = 0; i < 3; ++i) w.force_N[i] += scale * steady[i];
  }
  return w;
}

std::string Disturbance::describe() const {
  if (!enabled) return "none";
  // Every field whose value in default_strike() is not zero is written, so
  // that parse_disturbance (which starts from the default) reads it back.
  std::string out = "strike:period=" + std::to_string(period_steps) + ",duration=" + std::to_string(duration_steps) +
                    ",start=" + std::to_string(start_step) + ",force=" + vector_text(force_N);
  if (!all_zero(torque_Nm)) out += ",torque=" + vector_text(torque_Nm);
  out += ",ramp=" + std::to_string(ramp_strikes);
  if (!all_zero(drift_N_per_step)) out += ",drift=" + vector_text(drift_N_per_step);
  if (drift_max_N > 0) out += ",drift_max=" + number_text(drift_max_N);
  out += frame == DisturbanceFrame::kRadial ? ",frame=radial" : ",frame=world";
  return out;
}

Disturbance default_strike() {
  // One strike a second, each 0.2 s long, pushing the object towards the
  // wrist (radially, so that the wrist muscles do not carry it), growing
  // over the first 10 strikes to 8 N. docs/plant.md gives the measurements
  // behind these numbers.
  Disturbance d;
  d.enabled = true;
  d.period_steps = 5;
  d.duration_steps = 1;
  d.start_step = 5;
  d.force_N = {-8.0, 0.0, 0.0};
  d.ramp_strikes = 10;
  d.frame = DisturbanceFrame::kRadial;
  return d;
}

std::string parse_disturbance(std::string_view text, Disturbance& out) {
  if (text == "none" || text == "off") {
    out = Disturbance{};
    return "";
  }
  const std::string_view kind = text.substr(0, text.find(':'));
  if (kind == "none" || kind == "off") return "disturbance '" + std::string(kind) + "' takes no fields";
  if (kind != "strike")
    return "unknown disturbance '" + std::string(kind) + "' (expected none, off or strike[:FIELD=VALUE,...])";
  Disturbance d = default_strike();
  if (kind.size() < text.size()) {
    std::vector<Field> fields;
    if (auto e = split_fields(text.substr(kind.size() + 1), fields); !e.empty()) return "disturbance: " + e;
    std::vector<std::string> seen;
    for (const auto& f : fields) {
      if (std::find(seen.begin(), seen.end(), f.name) != seen.end()) return field_error(f, "given twice");
      seen.push_back(f.name);
      std::string e;
      if (f.name == "period") {
        e = read_count(f, 1, d.period_steps);
      } else if (f.name == "duration") {
        e = read_count(f, 1, d.duration_steps);
      } else if (f.name == "start") {
        e = read_count(f, 0, d.start_step);
      } else if (f.name == "ramp") {
        e = read_count(f, 0, d.ramp_strikes);
      } else if (f.name == "force") {
        e = read_vector(f, d.force_N);
      } else if (f.name == "torque") {
        e = read_vector(f, d.torque_Nm);
      } else if (f.name == "drift") {
        e = read_vector(f, d.drift_N_per_step);
      } else if (f.name == "drift_max") {
        e = read_scalar(f, d.drift_max_N);
        if (e.empty() && d.drift_max_N < 0) e = field_error(f, "must be >= 0");
      } else if (f.name == "frame") {
        const std::string_view value = f.values.size() == 1 ? f.values[0] : std::string_view();
        if (value == "world") {
          d.frame = DisturbanceFrame::kWorld;
        } else if (value == "radial") {
          d.frame = DisturbanceFrame::kRadial;
        } else {
          e = field_error(f, "expected world or radial");
        }
      } else {
        e = "unknown disturbance field '" + f.name +
            "' (expected period, duration, start, force, torque, ramp, drift, drift_max or frame)";
      }
      if (!e.empty()) return e;
    }
  }
  if (d.duration_steps > d.period_steps)
    return "disturbance field 'duration': " + std::to_string(d.duration_steps) + " steps exceed the period of " +
           std::to_string(d.period_steps);
  out = d;
  return "";
}

}  // namespace hadynet::plant
