// hadynet replay: host-sim — the firmware core compiled for the PC with the
// build's generated model (codegen of HADYNET_MODEL), fed a recorded log
// frame by frame. Writes per step the estimate of y_t, d, the contact flag
// and the stabiliser's command as CSV; prints a summary; --plot draws d and
// the commands.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/gnuplot.h"
#include "cli/options.h"
#include "datalog/log_error.h"
#include "datalog/log_reader.h"
#include "host-sim/replay/replay.h"
#include "tools/link/fd_stream.h"

namespace hadynet::cli {

namespace {

std::string replay_plot(const hostsim::ReplayResult& r, const hostsim::CompiledModelInfo& info,
                        const std::string& title, const std::string& png) {
  std::string s = "$d << EOD\n";
  char buf[64];
  for (const auto& st : r.steps) {
    if (!st.distance_valid) continue;
    std::snprintf(buf, sizeof buf, "%.4f %.6g\n", st.time, static_cast<double>(st.d));
    s += buf;
  }
  s += "EOD\n$u << EOD\n";
  bool any_command = false;
  for (const auto& st : r.steps) {
    if (!st.command_valid) continue;
    any_command = true;
    std::snprintf(buf, sizeof buf, "%.4f", st.time);
    s += buf;
    for (float v : st.command) {
      std::snprintf(buf, sizeof buf, " %.6g", static_cast<double>(v));
      s += buf;
    }
    s += "\n";
  }
  s += "EOD\n";
  s += "set terminal pngcairo size 1200,700 font 'sans,9' noenhanced\n";
  s += "set output " + gnuplot_quote(png) + "\n";
  s += "set multiplot layout 2,1 title " + gnuplot_quote(title) + "\nset grid\nset xlabel 't [s]'\n";
  s += "set ylabel 'd'\nset logscale y\n";
  std::snprintf(buf, sizeof buf, "%.6g", static_cast<double>(info.detect_threshold));
  s += "plot $d using 1:2 with lines title 'd', " + std::string(buf) +
       " with lines dt 2 lw 2 lc rgb 'red' title 'C_detect'\n";
  s += "unset logscale y\nset ylabel 'stabiliser command u_t'\n";
  if (any_command) {
    s += "plot ";
    for (std::size_t i = 0; i < r.u_names.size(); ++i) {
      if (i) s += ", ";
      s += "$u using 1:" + std::to_string(i + 2) + " with lines title " + gnuplot_quote(r.u_names[i]);
    }
    s += "\n";
  } else {
    s += "set label 1 'no control (see --control-from)' at graph 0.4,0.5\nplot 0 notitle\n";
  }
  s += "unset multiplot\n";
  return run_gnuplot(s, png);
}

}  // namespace

int run_replay(int argc, char** argv) {
  Options opt("replay",
              "Host-sim: replays a recorded log through the firmware core built for the PC with the\n"
              "model compiled into this build (codegen of the CMake variable HADYNET_MODEL). Frame t\n"
              "carries y_t and the command u_{t-1}; the firmware returns its estimate of y_t from\n"
              "x_{t-N} and u_[t-N,t) (N = N_detect), the Mahalanobis distance d, the contact flag\n"
              "d > C_detect and, in control mode, the grasp stabiliser's command u_t (advisory: the\n"
              "log's own commands keep driving the replay). Bit-identical across runs.\n"
              "--target qemu runs the same log through a firmware image in QEMU instead, and\n"
              "--target serial/tcp through a device on a serial port or socket, frame by frame over\n"
              "the link protocol (docs/protocol.md); the device must run this build's model.\n"
              "--adapt switches the firmware's PB adaptation on (docs/firmware.md, \"Adapting the PB on\n"
              "the device\"): the CSV gains the adapted PB and its nearest trained states per row. Several\n"
              "LOGs run one after the other through one device, reset between them (a new recording;\n"
              "the PB and its adaptation carry over, as when the grasped object changes).",
              "LOG... --out CSV [options]");
  opt.value("target", "hostsim|qemu|serial|tcp", "where the firmware runs", "hostsim");
  opt.value("image", "ELF", "firmware image for --target qemu", HADYNET_DEFAULT_QEMU_IMAGE);
  opt.value("machine", "NAME", "QEMU machine for --target qemu (mps2-an386, netduinoplus2)", "mps2-an386");
  opt.value("qemu-log", "FILE", "QEMU's own output (--target qemu)");
  opt.value("qemu-load", "FILE@ADDRESS",
            "--target qemu: place FILE's bytes at ADDRESS in the guest before it starts (e.g. a model slot's\n"
            "contents at 0x08080000 on netduinoplus2)");
  opt.value("device", "PATH", "serial device for --target serial (e.g. /dev/ttyACM0, a pty)");
  opt.value("baud", "N", "baud rate for --target serial", "115200");
  opt.value("tcp", "HOST:PORT", "socket for --target tcp (e.g. QEMU's -serial tcp:...)");
  opt.value("out", "CSV", "per-step results (required)");
  opt.value("numeric", "q15|f32", "which generated build of the core", "q15");
  opt.value("mode", "observe|detect|control", "firmware mode from the first row", "detect");
  opt.value("control-from", "ROW", "switch to control mode at this row (y_ref = its y)");
  opt.value("pb", "STATE|v1,..,vP", "PB: a state name of the PB table or standardised values "
            "(default: the detection PB)");
  opt.value("control-epochs", "N", "stabiliser epochs (default: the model's)");
  opt.value("control-truncation", "K", "stabiliser truncation depth K (default: the model's)");
  opt.flag("adapt", "adapt the PB on the device from the first row, starting from the active PB (--target hostsim)");
  opt.value("adapt-stride", "N", "--adapt: an epoch runs every N-th window (default: the firmware's)");
  opt.value("adapt-budget", "N", "--adapt: windows run per period (default: the firmware's)");
  opt.value("plot", "PNG", "draw d and the commands");
  opt.flag("info", "print the compiled model's identity and sizes and exit");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;

  hostsim::ReplayOptions ro;
  const auto parsed_numeric = opt.get_numeric("numeric");
  if (!parsed_numeric) return 2;
  ro.numeric = *parsed_numeric;
  const std::string numeric = firmware::numeric_name(ro.numeric);
  const hostsim::CompiledModelInfo info = hostsim::compiled_model_info(ro.numeric);
  if (opt.has("info")) {
    std::printf("compiled model (%s): %s, hash %016llx\n", numeric.c_str(), info.generator.c_str(),
                static_cast<unsigned long long>(info.hash));
    std::printf("dims: x %d, u %d, y %d, pb %d, hidden %d, states %d\n", info.x, info.u, info.y, info.pb,
                info.hidden, info.states);
    std::printf("detection: %s (N_detect %d, C_detect %g)\n", info.has_detection ? "yes" : "no",
                info.detect_steps, static_cast<double>(info.detect_threshold));
    std::printf("stabiliser: horizon %d, epochs %d, truncation %d\n", info.control_horizon, info.control_epochs,
                info.control_truncation);
    return 0;
  }
  if (opt.positional().empty() || !opt.has("out")) {
    std::fprintf(stderr, "hadynet replay: need a LOG and --out CSV (see --help)\n");
    return 2;
  }
  ro.adapt = opt.has("adapt");
  if (!ro.adapt && (opt.has("adapt-stride") || opt.has("adapt-budget"))) {
    std::fprintf(stderr, "hadynet replay: --adapt-stride and --adapt-budget need --adapt\n");
    return 2;
  }
  if (opt.has("adapt-stride")) {
    const auto v = opt.get_int("adapt-stride", 1, 200);
    if (!v) return 2;
    ro.adapt_window_stride = static_cast<int>(*v);
  }
  if (opt.has("adapt-budget")) {
    const auto v = opt.get_int("adapt-budget", 1, 200);
    if (!v) return 2;
    ro.adapt_windows_per_period = static_cast<int>(*v);
  }
  const std::string mode = opt.get("mode");
  if (mode == "observe") {
    ro.mode = firmware::Mode::kObserve;
  } else if (mode == "detect") {
    ro.mode = firmware::Mode::kDetect;
  } else if (mode == "control") {
    ro.mode = firmware::Mode::kDetect;
    ro.control_from = 0;
  } else {
    std::fprintf(stderr, "hadynet replay: --mode must be observe, detect or control\n");
    return 2;
  }
  if (opt.has("control-from")) {
    const auto v = opt.get_int("control-from", 0, 1 << 30);
    if (!v) return 2;
    ro.control_from = static_cast<int>(*v);
  }
  if (opt.has("control-epochs")) {
    const auto v = opt.get_int("control-epochs", 0, 100);
    if (!v) return 2;
    ro.control_epochs = static_cast<int>(*v);
  }
  if (opt.has("control-truncation")) {
    const auto v = opt.get_int("control-truncation", 1, 1000);
    if (!v) return 2;
    ro.control_truncation = static_cast<int>(*v);
  }
  if (opt.has("pb")) {
    const std::string pb = opt.get("pb");
    for (std::size_t k = 0; k < info.state_names.size(); ++k)
      if (info.state_names[k] == pb) ro.pb_state = static_cast<int>(k);
    if (ro.pb_state < 0) {
      std::size_t pos = 0;
      try {
        while (pos <= pb.size()) {
          const std::size_t comma = pb.find(',', pos);
          const std::string field = pb.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
          std::size_t used = 0;
          ro.pb.push_back(std::stof(field, &used));
          if (used != field.size()) throw std::invalid_argument(field);
          if (comma == std::string::npos) break;
          pos = comma + 1;
        }
      } catch (const std::exception&) {
        std::fprintf(stderr, "hadynet replay: --pb '%s' is neither a state of the model nor %d numbers\n",
                     pb.c_str(), info.pb);
        return 2;
      }
    }
  }

  if (!ro.pb.empty() && static_cast<int>(ro.pb.size()) != info.pb) {
    std::fprintf(stderr, "hadynet replay: --pb has %zu values, the compiled model's PB has %d\n", ro.pb.size(),
                 info.pb);
    return 2;
  }
  const std::string log_path = opt.positional()[0];
  const std::string target = opt.get("target");
  std::unique_ptr<tools::FdStream> stream;
  try {
    if (target == "qemu") {
      ro.target = hostsim::ReplayTarget::kQemu;
      ro.qemu_image = opt.get("image");
      ro.qemu_machine = opt.get("machine");
      ro.qemu_log = opt.get("qemu-log");
      if (opt.has("qemu-load")) {
        const auto load = tools::parse_qemu_load(opt.get("qemu-load"));
        if (!load) {
          std::fprintf(stderr, "hadynet replay: --qemu-load wants FILE@ADDRESS, got '%s'\n",
                       opt.get("qemu-load").c_str());
          return 2;
        }
        ro.qemu_loads.push_back(*load);
      }
    } else if (target == "serial" || target == "tcp") {
      if (target == "serial") {
        const auto baud = opt.get_int("baud", 1, 10000000);
        if (!baud || !opt.has("device")) {
          std::fprintf(stderr, "hadynet replay: --target serial needs --device PATH (and a valid --baud)\n");
          return 2;
        }
        stream = std::make_unique<tools::FdStream>(tools::FdStream::open_serial(opt.get("device"), static_cast<int>(*baud)));
      } else {
        const auto host_port = tools::parse_host_port(opt.get("tcp"));
        if (!host_port) {
          std::fprintf(stderr, "hadynet replay: --tcp needs HOST:PORT, not '%s'\n", opt.get("tcp").c_str());
          return 2;
        }
        stream = std::make_unique<tools::FdStream>(
            tools::FdStream::connect_tcp(host_port->first, host_port->second, 5000));
      }
      ro.target = hostsim::ReplayTarget::kStream;
      ro.stream = stream.get();
    } else if (target != "hostsim") {
      std::fprintf(stderr, "hadynet replay: --target must be hostsim, qemu, serial or tcp, not '%s'\n",
                   target.c_str());
      return 2;
    }
    std::vector<datalog::LogTable> logs;
    for (const std::string& path : opt.positional()) logs.push_back(datalog::read_log(path));
    const hostsim::ReplayResult r = hostsim::replay_logs(logs, opt.positional(), ro);
    {
      std::ofstream out(opt.get("out"), std::ios::binary);
      out << hostsim::format_replay_csv(r);
      if (!out.flush()) throw std::runtime_error(opt.get("out") + ": cannot write");
    }
    int distances = 0, flagged = 0, commands = 0;
    double d_max = 0.0;
    for (const auto& st : r.steps) {
      if (st.distance_valid) {
        ++distances;
        flagged += st.contact ? 1 : 0;
        d_max = std::max(d_max, static_cast<double>(st.d));
      }
      commands += st.command_valid ? 1 : 0;
    }
    const std::string what = logs.size() == 1 ? log_path : std::to_string(logs.size()) + " logs";
    std::printf("%s: %zu rows (%s), d on %d rows, contact on %d (%.1f%%), max d %.3g, %d commands -> %s\n",
                what.c_str(), r.steps.size(), numeric.c_str(), distances, flagged,
                distances ? 100.0 * flagged / distances : 0.0, d_max, commands, opt.get("out").c_str());
    if (r.adapt && !r.steps.empty()) {
      for (std::size_t k = 0; k < logs.size(); ++k) {
        const std::size_t last = k + 1 < r.log_first_step.size() ? r.log_first_step[k + 1] - 1 : r.steps.size() - 1;
        const hostsim::ReplayStep& st = r.steps[last];
        if (st.recognized_state < 0) {
          std::printf("  %s: adapted PB: no step yet (%u)\n", opt.positional()[k].c_str(), st.adapt_updates);
          continue;
        }
        std::printf("  %s: adapted PB after %u steps: nearest %s (distance %.3g), other object %s (%.3g)\n",
                    opt.positional()[k].c_str(), st.adapt_updates,
                    r.state_names[static_cast<std::size_t>(st.recognized_state)].c_str(),
                    static_cast<double>(st.recognized_distance),
                    st.other_state >= 0 ? r.state_names[static_cast<std::size_t>(st.other_state)].c_str() : "-",
                    static_cast<double>(st.other_distance));
      }
    }
    if (opt.has("plot")) {
      const std::string err = replay_plot(r, info, std::filesystem::path(log_path).filename().string() + " (" +
                                                       numeric + ")", opt.get("plot"));
      if (!err.empty()) {
        std::fprintf(stderr, "hadynet replay: %s\n", err.c_str());
        return 1;
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet replay: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
