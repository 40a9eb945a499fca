// Host-sim replay: the firmware core, built for the PC from the same sources,
// fed a recorded log frame by frame (hadynet replay). Per step it records
// what the firmware would report: HADYNET's estimate of y_t, the contact
// distance d and flag, and the grasp stabiliser's command. Deterministic:
// the same log and options give bit-identical results (q15 and f32 alike).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "datalog/log_table.h"
#include "firmware/core/hadynet_runtime.h"
#include "tools/link/byte_stream.h"
#include "tools/link/qemu_process.h"

namespace hadynet::hostsim {


// Where the firmware runs: the core compiled into this program (host-sim),
// a firmware image in QEMU, or any device on a byte stream (a serial port),
// the last two over the serial link (docs/protocol.md).
enum class ReplayTarget { kHostSim, kQemu, kStream };

struct ReplayOptions {
  firmware::Numeric numeric = firmware::Numeric::kQ15;
  firmware::Mode mode = firmware::Mode::kDetect;  // mode before control_from
  int control_from = -1;       // row at which control mode starts (y_ref = y of that row); -1 never
  int pb_state = -1;           // PB table row; -1: the model's default (detection PB)
  std::vector<float> pb;       // explicit standardised PB; overrides pb_state if non-empty
  int control_epochs = -1;     // -1: the model's default
  int control_truncation = -1; // -1: the model's default
  bool adapt = false;          // PB adaptation on from the first row (firmware/core/pb_adapter.h)
  int adapt_window_stride = -1;       // -1: the firmware's default
  int adapt_windows_per_period = -1;  // -1: the firmware's default
  ReplayTarget target = ReplayTarget::kHostSim;
  std::string qemu_image;      // firmware ELF (target qemu); its model must be the compiled-in one
  std::string qemu_machine = "mps2-an386";
  std::string qemu_log;        // QEMU's output ("" : discarded)
  std::vector<tools::QemuOptions::Load> qemu_loads;  // files placed into the guest (e.g. a model slot)
  tools::ByteStream* stream = nullptr;  // target stream: the open link (not owned)
};

// One replayed step (log row t). Physical units except d and the losses
// (standardised, as the firmware computes them).
struct ReplayStep {
  double time = 0.0;
  bool prediction_valid = false;
  std::vector<float> prediction;  // y_est_t
  bool distance_valid = false;
  float d = 0.0f;
  bool contact = false;
  bool command_valid = false;
  std::vector<float> command;  // u_t from the stabiliser
  double loss_initial = 0.0;   // stabiliser: L of the warm start
  double loss_final = 0.0;     // stabiliser: L of the adopted sequence
  // PB adaptation (options.adapt): steps taken, the adapted PB (standardised)
  // and its nearest trained states (-1: none yet).
  std::uint32_t adapt_updates = 0;
  std::vector<float> adapted_pb;
  int recognized_state = -1;
  float recognized_distance = 0.0f;
  int other_state = -1;
  float other_distance = 0.0f;
};

struct ReplayResult {
  std::vector<std::string> y_names, u_names, state_names;
  bool adapt = false;  // the steps carry the adaptation's columns
  std::vector<ReplayStep> steps;
  std::vector<std::size_t> log_first_step;  // index of each log's first step (replay_logs)
};

// What the compiled-in generated model is (for --help, info and checks).
struct CompiledModelInfo {
  std::string generator;
  std::uint64_t hash = 0;
  int x = 0, u = 0, y = 0, pb = 0, hidden = 0, states = 0, detect_steps = 0;
  bool has_detection = false;
  float detect_threshold = 0.0f;  // C_detect
  int control_horizon = 0, control_epochs = 0, control_truncation = 0;
  std::vector<std::string> y_names, u_names, state_names;
};
CompiledModelInfo compiled_model_info(firmware::Numeric numeric);

// Replays `log` (read from `file`, named in errors). Throws
// std::runtime_error naming the file if the log lacks a channel of the
// compiled model, std::invalid_argument for bad options (PB size or state,
// stabiliser settings with target qemu), tools::LinkError if the device
// fails or runs another model (its info's hash differs). With target qemu
// the stabiliser's losses are not reported (0).
ReplayResult replay_log(const datalog::LogTable& log, const std::string& file,
                        const ReplayOptions& options);
// Several logs through one device, one after the other: the device is reset
// between them (a new recording: no window or history spans two logs), its
// PB, mode and adaptation carry over (an object change mid-stream).
ReplayResult replay_logs(const std::vector<datalog::LogTable>& logs, const std::vector<std::string>& files,
                         const ReplayOptions& options);

// CSV: t, valid flags, y_est_<y>..., d, contact, u_<u>..., losses, and with
// adaptation: log, adapt_updates, pb_0.., recognized (state name), distance,
// other (nearest state of another object), other_distance; floats with 9
// significant digits (float round trip).
std::string format_replay_csv(const ReplayResult& result);

}  // namespace hadynet::hostsim
