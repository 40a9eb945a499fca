#include "host-sim/plant/grasp_session.h"

#include <cctype>
#include <cmath>
#include <stdexcept>

namespace hadynet::plant {

namespace {

ExperimentSpec session_spec(ObjectKind object, int init_id, double wear_level, std::uint64_t seed) {
  ExperimentSpec s;
  s.object = object;
  s.init_id = init_id;
  s.wear_level = wear_level;
  s.seed = seed;
  return s;
}

// Forces the grasp of the spec's Random-2 log; the step count is not used.
ExperimentSpec as_random2(ExperimentSpec spec) {
  spec.motion = Motion::kRandom2;
  spec.steps = kGraspSteps;
  return spec;
}

using Vec3 = std::array<double, 3>;
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 normalised(Vec3 v) {
  const double n = std::sqrt(dot(v, v));
  for (auto& c : v) c /= n;
  return v;
}

// Axes (in world coordinates) of DisturbanceFrame::kRadial for the plant's
// current pose; the world axes when there is no object.
std::array<Vec3, 3> radial_frame(const HandPlant& plant) {
  std::array<Vec3, 3> axes = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  if (!plant.has_object()) return axes;
  const Vec3 com = plant.object_position_m(), centre = plant.wrist_centre_m();
  Vec3 x = {com[0] - centre[0], com[1] - centre[1], com[2] - centre[2]};
  if (dot(x, x) < 1e-12) return axes;
  x = normalised(x);
  // z: world up without its x part (world x if x is vertical).
  const Vec3 up = std::abs(x[2]) < 0.99 ? Vec3{0, 0, 1} : Vec3{1, 0, 0};
  const double along = dot(up, x);
  const Vec3 z = normalised({up[0] - along * x[0], up[1] - along * x[1], up[2] - along * x[2]});
  return {x, cross(z, x), z};
}

bool is_prefix_digits(const std::string& name, const char* prefix) {
  const std::string p(prefix);
  if (name.size() <= p.size() || name.compare(0, p.size(), p) != 0) return false;
  for (std::size_t i = p.size(); i < name.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(name[i]))) return false;
  return true;
}

}  // namespace

GraspSession::GraspSession(ObjectKind object, int init_id, double wear_level, std::uint64_t seed,
                           const Disturbance& disturbance, int hold_steps)
    : GraspSession(session_spec(object, init_id, wear_level, seed), disturbance, hold_steps) {}

GraspSession::GraspSession(const ExperimentSpec& spec, const Disturbance& disturbance, int hold_steps)
    : spec_(as_random2(spec)), disturbance_(disturbance), hold_steps_(hold_steps) {
  if (disturbance_.enabled && spec_.object == ObjectKind::kNone)
    throw std::invalid_argument("grasp session: a disturbance needs a grasped object (object is None)");
  if (hold_steps_ < 0) throw std::invalid_argument("grasp session: hold_steps must be >= 0");
  loop_ = std::make_unique<ExperimentLoop>(spec_);
  // The grasp phase of the state's Random-2 log: same motion stream, same
  // rounding, no disturbance. Then hold it.
  MotionGenerator motion(Motion::kRandom2, spec_.object, motion_seed(spec_));
  for (int k = 0; k < kGraspSteps; ++k) loop_->apply(loop_->command_to(motion.next_target()));
  for (int k = 0; k < hold_steps_; ++k) loop_->apply({});
  radial_axes_ = radial_frame(loop_->plant());
  y_names_ = observed_channel_names();
  u_names_ = command_channel_names();
  append_observed(loop_->measured(), y_);
  y_grasp_ = y_;
  last_u_.assign(u_names_.size(), 0.0);
}

GraspSession::~GraspSession() = default;
GraspSession::GraspSession(GraspSession&&) noexcept = default;
GraspSession& GraspSession::operator=(GraspSession&&) noexcept = default;

const std::array<double, kMuscles>& GraspSession::target_mm() const { return loop_->target_mm(); }
const HandPlant& GraspSession::plant() const { return loop_->plant(); }

void GraspSession::step(const std::vector<double>& u) {
  if (u.size() != u_names_.size())
    throw std::invalid_argument("grasp session: u has " + std::to_string(u.size()) + " entries, expected " +
                                std::to_string(u_names_.size()));
  std::array<double, kMuscles> command{};
  for (int m = 0; m < kMuscles; ++m) {
    if (!std::isfinite(u[m])) throw std::invalid_argument("grasp session: u" + std::to_string(m) + " is not finite");
    command[m] = u[m];
  }
  const Wrench w = next_wrench();
  loop_->plant().set_object_wrench(w.force_N, w.torque_Nm);
  const auto applied = loop_->apply(command);
  last_wrench_ = w;
  last_u_.assign(applied.begin(), applied.end());
  radial_axes_ = radial_frame(loop_->plant());  // for the next step
  y_.clear();
  append_observed(loop_->measured(), y_);
  ++step_index_;
}

Wrench GraspSession::to_world(const Wrench& w) const {
  if (disturbance_.frame == DisturbanceFrame::kWorld) return w;
  Wrench out;
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a) {
      out.force_N[i] += w.force_N[a] * radial_axes_[a][i];
      out.torque_Nm[i] += w.torque_Nm[a] * radial_axes_[a][i];
    }
  return out;
}

double grasp_error(const std::vector<double>& y, const std::vector<double>& y_ref, double beta,
                   const std::vector<std::size_t>& channels) {
  if (y.size() != y_ref.size())
    throw std::invalid_argument("grasp_error: y has " + std::to_string(y.size()) + " entries, y_ref " +
                                std::to_string(y_ref.size()));
  double e = 0;
  for (std::size_t i : channels) {
    if (i >= y.size()) throw std::invalid_argument("grasp_error: channel index " + std::to_string(i) + " out of range");
    const double d = y[i] - y_ref[i];
    e += (d >= 0 ? 1.0 : beta) * d * d;
  }
  return e;
}

std::vector<std::size_t> force_channels(const std::vector<std::string>& names, bool tensions, bool loadcells) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < names.size(); ++i)
    if ((tensions && is_prefix_digits(names[i], "f")) || (loadcells && is_prefix_digits(names[i], "fc")))
      out.push_back(i);
  return out;
}

double grasp_error(const std::vector<double>& y, const std::vector<double>& y_ref,
                   const std::vector<std::string>& names, double beta) {
  return grasp_error(y, y_ref, beta, force_channels(names));
}

}  // namespace hadynet::plant
