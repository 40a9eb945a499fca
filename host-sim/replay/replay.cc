#include "host-sim/replay/replay.h"

#include <cstdio>
#include <memory>
#include <stdexcept>

#include "datalog/log_limits.h"
#include "datalog/log_reader.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "host-sim/channel_binding.h"
#include "tools/link/link_session.h"
#include "tools/link/qemu_process.h"

namespace hadynet::hostsim {

namespace {

template <class M>
CompiledModelInfo info_of() {
  CompiledModelInfo info;
  info.generator = M::kGeneratorVersion;
  info.hash = M::kModelHash;
  info.x = M::kX;
  info.u = M::kU;
  info.y = M::kY;
  info.pb = M::kPb;
  info.hidden = M::kHidden;
  info.states = M::kStates;
  info.detect_steps = M::kDetectSteps;
  info.has_detection = M::kHasDetection;
  info.detect_threshold = M::kDetectThreshold;
  info.control_horizon = M::kControlHorizon;
  info.control_epochs = M::kControlEpochs;
  info.control_truncation = M::kControlTruncation;
  for (int i = 0; i < M::kY; ++i) info.y_names.emplace_back(M::kYNames[i]);
  for (int i = 0; i < M::kU; ++i) info.u_names.emplace_back(M::kUNames[i]);
  for (int i = 0; i < M::kStates; ++i) info.state_names.emplace_back(M::kStateNames[i]);
  return info;
}

// The adaptation's columns of a replayed step from the device's status.
template <class M>
void fill_adapt(const link::AdaptStatus<M>& a, ReplayStep& s) {
  s.adapt_updates = a.updates;
  s.adapted_pb.assign(a.pb, a.pb + M::kPb);
  if (a.state != link::kNoState) {
    s.recognized_state = a.state;
    s.recognized_distance = a.distance;
  }
  if (a.other_state != link::kNoState) {
    s.other_state = a.other_state;
    s.other_distance = a.other_distance;
  }
}

// The firmware compiled into this program.
template <class M>
class HostDevice {
 public:
  explicit HostDevice(const ReplayOptions& opt) : rt_(std::make_unique<firmware::HadynetRuntime<M>>()) {
    if (opt.control_epochs >= 0) rt_->control_settings().epochs = opt.control_epochs;
    if (opt.control_truncation >= 1) rt_->control_settings().truncation = opt.control_truncation;
  }
  void start_adapting(const ReplayOptions& opt) {
    typename firmware::PbAdapter<M>::Settings s = rt_->adapter().settings();
    if (opt.adapt_window_stride > 0) s.window_stride = opt.adapt_window_stride;
    if (opt.adapt_windows_per_period > 0) s.windows_per_period = opt.adapt_windows_per_period;
    if (!rt_->set_adapt_settings(s)) throw std::invalid_argument("PB adaptation: invalid stride or budget");
    rt_->set_adapting(true);
  }
  void reset() { rt_->reset(); }
  void set_pb(const float (&pb)[M::kPb]) { rt_->set_pb(pb); }
  bool set_pb_state(int state) { return rt_->set_pb_state(state); }
  void set_mode(firmware::Mode mode) { rt_->set_mode(mode); }
  firmware::StepResult<M> step(const firmware::SensorFrame<M>& frame, ReplayStep& s) {
    const firmware::StepResult<M> r = rt_->step(frame);
    if (rt_->adapting()) fill_adapt<M>(link::adapt_status_of(*rt_), s);
    if (r.command_valid) {
      s.loss_initial = firmware::GraspStabilizer<M>::loss_value(rt_->stabilizer().loss_initial());
      s.loss_final = firmware::GraspStabilizer<M>::loss_value(rt_->stabilizer().loss_final());
    }
    return r;
  }

 private:
  // The runtime holds the network, traces and history (~tens of KiB): on
  // the heap here, a static object on the MCU.
  std::unique_ptr<firmware::HadynetRuntime<M>> rt_;
};

// A device running the firmware, over its serial link.
template <class M>
class LinkDevice {
 public:
  LinkDevice(tools::ByteStream& stream, const ReplayOptions& opt) : session_(stream) {
    if (opt.control_epochs >= 0 || opt.control_truncation >= 1)
      throw std::invalid_argument("stabiliser settings cannot be changed over the link");
    session_.connect();
    const link::InfoReply info = session_.info();
    if (info.model_hash != M::kModelHash || info.numeric != (firmware::kIsFixed<M> ? 0 : 1))
      throw tools::LinkError(stream.name() + ": the device runs another model or numeric than this build");
  }
  void set_pb(const float (&pb)[M::kPb]) { session_.set_pb(pb); }
  bool set_pb_state(int state) {
    if (state < 0 || state >= M::kStates) return false;
    session_.set_pb_state(static_cast<std::uint16_t>(state));
    return true;
  }
  void set_mode(firmware::Mode mode) { session_.set_mode(mode); }
  void start_adapting(const ReplayOptions& opt) {
    link::AdaptRequest q;
    q.action = link::AdaptAction::kOn;
    q.window_stride = static_cast<std::uint8_t>(opt.adapt_window_stride > 0 ? opt.adapt_window_stride : 0);
    q.windows_per_period =
        static_cast<std::uint8_t>(opt.adapt_windows_per_period > 0 ? opt.adapt_windows_per_period : 0);
    session_.adapt(q);
    adapting_ = true;
  }
  void reset() { session_.reset(); }
  // The step result, and with adaptation on its status (a second exchange).
  firmware::StepResult<M> step(const firmware::SensorFrame<M>& frame, ReplayStep& s) {
    const firmware::StepResult<M> r = session_.step(frame);
    if (adapting_) fill_adapt<M>(session_.adapt({}), s);
    return r;
  }

 private:
  tools::LinkSession<M> session_;
  bool adapting_ = false;
};

template <class M, class Device>
void replay_one(Device& device, const datalog::LogTable& log, const std::string& file, const ReplayOptions& opt,
                ReplayResult& result) {
  const ChannelBinding binding = bind_channels<M>(log.columns, log.columns, file, "column", "column");
  const auto t_col = log.column_index("t");
  std::vector<std::size_t> signal_cols = binding.y;
  for (const std::size_t c : binding.u)
    if (c != ChannelBinding::kComputed) signal_cols.push_back(c);
  datalog::check_magnitudes(log, signal_cols, datalog::kMaxSignalMagnitude, file,
                            "the firmware's boundary is float32 (docs/input-limits.md)");
  result.log_first_step.push_back(result.steps.size());
  firmware::SensorFrame<M> frame{};
  for (std::size_t row = 0; row < log.rows(); ++row) {
    if (opt.control_from >= 0 && row == static_cast<std::size_t>(opt.control_from))
      device.set_mode(firmware::Mode::kControl);
    // u_{t-1}: none before the first row.
    fill_frame<M>(
        binding, [&](std::size_t c) { return log.at(row, c); },
        [&](std::size_t c) { return row == 0 ? 0.0 : log.at(row - 1, c); }, frame);
    ReplayStep s;
    const firmware::StepResult<M> r = device.step(frame, s);
    s.time = t_col ? log.at(row, *t_col) : static_cast<double>(row);
    s.prediction_valid = r.prediction_valid;
    s.prediction.assign(r.prediction, r.prediction + M::kY);
    s.distance_valid = r.distance_valid;
    s.d = r.d;
    s.contact = r.contact;
    s.command_valid = r.command_valid;
    s.command.assign(r.command, r.command + M::kU);
    result.steps.push_back(std::move(s));
  }
}

template <class M, class Device>
ReplayResult replay_on(Device& device, const std::vector<datalog::LogTable>& logs,
                       const std::vector<std::string>& files, const ReplayOptions& opt) {
  const CompiledModelInfo info = info_of<M>();
  if (!opt.pb.empty()) {
    if (static_cast<int>(opt.pb.size()) != M::kPb)
      throw std::invalid_argument("PB has " + std::to_string(opt.pb.size()) + " values, the model " +
                                  std::to_string(M::kPb));
    float pb[M::kPb];
    for (int i = 0; i < M::kPb; ++i) pb[i] = opt.pb[static_cast<std::size_t>(i)];
    device.set_pb(pb);
  } else if (opt.pb_state >= 0 && !device.set_pb_state(opt.pb_state)) {
    throw std::invalid_argument("PB state " + std::to_string(opt.pb_state) + " is not in the model's table (" +
                                std::to_string(M::kStates) + " states)");
  }
  device.set_mode(opt.mode);
  if (opt.adapt) device.start_adapting(opt);  // from the active PB

  ReplayResult result;
  result.y_names = info.y_names;
  result.u_names = info.u_names;
  result.state_names = info.state_names;
  result.adapt = opt.adapt;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    if (i > 0) device.reset();  // a new recording
    replay_one<M>(device, logs[i], files[i], opt, result);
  }
  return result;
}

template <class M>
ReplayResult replay_with(const std::vector<datalog::LogTable>& log, const std::vector<std::string>& file,
                         const ReplayOptions& opt) {
  switch (opt.target) {
    case ReplayTarget::kQemu: {
      tools::QemuProcess qemu({"qemu-system-arm", opt.qemu_machine, opt.qemu_image, false, opt.qemu_log, opt.qemu_loads});
      LinkDevice<M> device(qemu.link(), opt);
      return replay_on<M>(device, log, file, opt);
    }
    case ReplayTarget::kStream: {
      if (opt.stream == nullptr) throw std::invalid_argument("target stream without a stream");
      LinkDevice<M> device(*opt.stream, opt);
      return replay_on<M>(device, log, file, opt);
    }
    case ReplayTarget::kHostSim:
      break;
  }
  HostDevice<M> device(opt);
  return replay_on<M>(device, log, file, opt);
}

void append_float(std::string& s, double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, ",%.9g", v);
  s += buf;
}

}  // namespace

CompiledModelInfo compiled_model_info(firmware::Numeric numeric) {
  return numeric == firmware::Numeric::kQ15 ? info_of<model_q15::Model>() : info_of<model_f32::Model>();
}

ReplayResult replay_logs(const std::vector<datalog::LogTable>& logs, const std::vector<std::string>& files,
                         const ReplayOptions& options) {
  if (logs.size() != files.size() || logs.empty()) throw std::invalid_argument("replay: one file name per log");
  return options.numeric == firmware::Numeric::kQ15 ? replay_with<model_q15::Model>(logs, files, options)
                                                : replay_with<model_f32::Model>(logs, files, options);
}

ReplayResult replay_log(const datalog::LogTable& log, const std::string& file, const ReplayOptions& options) {
  return replay_logs({log}, {file}, options);
}

std::string format_replay_csv(const ReplayResult& result) {
  std::string s = "t,prediction_valid";
  for (const auto& n : result.y_names) s += ",est_" + n;
  s += ",distance_valid,d,contact,command_valid";
  for (const auto& n : result.u_names) s += ",cmd_" + n;
  s += ",loss_initial,loss_final";
  const std::size_t pb_size = result.steps.empty() ? 0 : result.steps.front().adapted_pb.size();
  if (result.adapt) {
    s += ",log,adapt_updates";
    for (std::size_t i = 0; i < pb_size; ++i) s += ",pb_" + std::to_string(i);
    s += ",recognized,distance,other,other_distance";
  }
  s += '\n';
  const auto state_name = [&](int k) {
    return k >= 0 && static_cast<std::size_t>(k) < result.state_names.size() ? result.state_names[static_cast<std::size_t>(k)]
                                                                            : std::string();
  };
  std::size_t log = 0;
  for (std::size_t step = 0; step < result.steps.size(); ++step) {
    const ReplayStep& st = result.steps[step];
    while (log + 1 < result.log_first_step.size() && result.log_first_step[log + 1] <= step) ++log;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", st.time);
    s += buf;
    s += st.prediction_valid ? ",1" : ",0";
    for (float v : st.prediction) append_float(s, v);
    s += st.distance_valid ? ",1" : ",0";
    append_float(s, st.d);
    s += st.contact ? ",1" : ",0";
    s += st.command_valid ? ",1" : ",0";
    for (float v : st.command) append_float(s, v);
    append_float(s, st.loss_initial);
    append_float(s, st.loss_final);
    if (result.adapt) {
      s += "," + std::to_string(log) + "," + std::to_string(st.adapt_updates);
      for (float v : st.adapted_pb) append_float(s, v);
      s += "," + state_name(st.recognized_state);
      append_float(s, st.recognized_distance);
      s += "," + state_name(st.other_state);
      append_float(s, st.other_distance);
    }
    s += '\n';
  }
  return s;
}

}  // namespace hadynet::hostsim
