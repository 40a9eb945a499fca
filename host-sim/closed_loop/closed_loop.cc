#include "host-sim/closed_loop/closed_loop.h"

#include <cmath>
#include <memory>
#include <stdexcept>

#include "firmware/core/hadynet_runtime.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "host-sim/channel_binding.h"
#include "host-sim/plant/grasp_session.h"

namespace hadynet::hostsim {

namespace {

template <class M>
ClosedLoopRun run_with(const ClosedLoopOptions& opt) {
  plant::ExperimentSpec spec;
  spec.object = opt.object;
  spec.init_id = opt.init_id;
  spec.wear_level = opt.wear_level;
  spec.seed = opt.seed;
  spec.effects = opt.effects;
  plant::GraspSession session(spec, opt.disturbance);
  // The model's channels in the plant's order; a derived input is computed
  // by the firmware from its base command, not sent to the plant (kNoCommand).
  constexpr std::size_t kNoCommand = ChannelBinding::kComputed;
  const auto derived = [](int i) { return M::kUDerived[i] != firmware::DerivedKind::kNone; };
  const ChannelBinding binding = bind_channels<M>(session.y_names(), session.u_names(), "the plant", "channel", "command");
  const std::vector<std::size_t>& u_index = binding.u;

  auto rt = std::make_unique<firmware::HadynetRuntime<M>>();
  if (!opt.pb_state.empty()) {
    int state = -1;
    for (int k = 0; k < M::kStates; ++k)
      if (opt.pb_state == M::kStateNames[k]) state = k;
    if (state < 0) throw std::invalid_argument("PB state '" + opt.pb_state + "' is not in the compiled model");
    rt->set_pb_state(state);
  }
  if (opt.control_epochs >= 0) rt->control_settings().epochs = opt.control_epochs;
  if (opt.control_truncation >= 1) rt->control_settings().truncation = opt.control_truncation;
  auto& settings = rt->control_settings();
  if (opt.absolute_reference) settings.reference = firmware::GraspStabilizer<M>::Reference::kAbsolute;
  if (opt.adopt_best_always) settings.keep_if_no_descent = false;
  if (opt.all_commands)
    for (int i = 0; i < M::kU; ++i) settings.active[i] = !derived(i);
  rt->set_mode(opt.control ? firmware::Mode::kControl : firmware::Mode::kDetect);

  ClosedLoopRun run;
  for (int i = 0; i < M::kU; ++i) run.u_names.emplace_back(M::kUNames[i]);
  const std::vector<double> y_ref = session.y_grasp();
  firmware::SensorFrame<M> frame{};
  std::vector<double> u(session.u_names().size(), 0.0);
  for (int t = 0; t <= opt.steps; ++t) {
    const std::vector<double>& y = session.y();
    fill_frame<M>(
        binding, [&](std::size_t k) { return y[k]; }, [&](std::size_t k) { return session.last_u()[k]; }, frame);
    const firmware::StepResult<M> r = rt->step(frame);
    ClosedLoopStep s;
    s.step = t;
    s.grasp_error = plant::grasp_error(y, y_ref, session.y_names());
    const auto& f = session.last_wrench().force_N;
    s.force_N = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    s.contact = r.contact;
    s.d = r.d;
    std::fill(u.begin(), u.end(), 0.0);
    if (opt.control && r.command_valid)
      for (int i = 0; i < M::kU; ++i)
        if (u_index[static_cast<std::size_t>(i)] != kNoCommand) u[u_index[static_cast<std::size_t>(i)]] = r.command[i];
    s.command.assign(M::kU, 0.0);
    for (int i = 0; i < M::kU; ++i)
      if (u_index[static_cast<std::size_t>(i)] != kNoCommand)
        s.command[static_cast<std::size_t>(i)] = u[u_index[static_cast<std::size_t>(i)]];
    if (opt.control && r.command_valid) {
      s.loss_initial = firmware::GraspStabilizer<M>::loss_value(rt->stabilizer().loss_initial());
      s.loss_final = firmware::GraspStabilizer<M>::loss_value(rt->stabilizer().loss_final());
    }
    run.steps.push_back(std::move(s));
    if (t < opt.steps) session.step(u);
  }
  return run;
}

}  // namespace

double ClosedLoopRun::mean_error(std::size_t begin, std::size_t end) const {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = begin; i < end && i < steps.size(); ++i, ++n) sum += steps[i].grasp_error;
  return n ? sum / static_cast<double>(n) : 0.0;
}

ClosedLoopRun run_closed_loop(const ClosedLoopOptions& options) {
  return options.numeric == firmware::Numeric::kQ15 ? run_with<model_q15::Model>(options)
                                                : run_with<model_f32::Model>(options);
}

}  // namespace hadynet::hostsim
