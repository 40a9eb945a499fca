// hadynet link: talk to a device running the firmware over its serial link
// (docs/protocol.md): a serial port, a TCP socket (e.g. QEMU's serial) or a
// QEMU machine started for the purpose. Actions: info, reset, mode, pb, adapt.
// Streaming a log through a device is `hadynet replay --target ...`.
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/options.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "tools/link/fd_stream.h"
#include "tools/link/link_session.h"
#include "tools/link/qemu_process.h"

namespace hadynet::cli {

namespace {

const char* mode_name(firmware::Mode m) {
  switch (m) {
    case firmware::Mode::kObserve: return "observe";
    case firmware::Mode::kDetect: return "detect";
    case firmware::Mode::kControl: return "control";
  }
  return "?";
}

// Runs one action on the device; returns the exit code.
template <class M>
int act(tools::ByteStream& stream, const std::vector<std::string>& action) {
  tools::LinkSession<M> session(stream);
  session.connect();  // a reset: synchronises the sequence numbers (and clears the history)
  const std::string& what = action[0];
  if (what == "info" || what == "reset") {
    const link::InfoReply i = session.info();
    std::printf("%s: protocol %u, contract %u, %s, model hash %016llx (%s)\n", stream.name().c_str(),
                i.protocol_version, i.contract_version, link::numeric_name(i.numeric),
                static_cast<unsigned long long>(i.model_hash), i.generator_version);
    std::printf("dims: x %u, u %u, y %u, pb %u, hidden %u, states %u; N_detect %u, horizon %u; detection %s (C %g)\n",
                i.x, i.u, i.y, i.pb, i.hidden, i.states, i.detect_steps, i.control_horizon,
                i.has_detection ? "yes" : "no", static_cast<double>(i.detect_threshold));
    std::printf("this build's model: hash %016llx%s\n", static_cast<unsigned long long>(M::kModelHash),
                i.model_hash == M::kModelHash ? " (the same)" : " (DIFFERENT: replay would refuse)");
    return 0;
  }
  if (what == "mode" && action.size() == 2) {
    firmware::Mode m;
    if (action[1] == "observe") {
      m = firmware::Mode::kObserve;
    } else if (action[1] == "detect") {
      m = firmware::Mode::kDetect;
    } else if (action[1] == "control") {
      m = firmware::Mode::kControl;
    } else {
      std::fprintf(stderr, "hadynet link: mode must be observe, detect or control\n");
      return 2;
    }
    session.set_mode(m);
    std::printf("%s: mode %s\n", stream.name().c_str(), mode_name(m));
    return 0;
  }
  if (what == "pb" && action.size() == 2) {
    for (int k = 0; k < M::kStates; ++k) {
      if (action[1] == M::kStateNames[k]) {
        // The row is looked up in this build's model: a device running
        // another model (a model image from a slot) may order its PB table
        // otherwise, so a state name is taken only for the same model.
        if (session.info().model_hash != M::kModelHash) {
          std::fprintf(stderr,
                       "hadynet link: %s runs another model than this build's (a model image?): its PB table's "
                       "rows may differ, so give the PB as %d comma-separated numbers\n",
                       stream.name().c_str(), M::kPb);
          return 1;
        }
        session.set_pb_state(static_cast<std::uint16_t>(k));
        std::printf("%s: PB of state %s (row %d)\n", stream.name().c_str(), M::kStateNames[k], k);
        return 0;
      }
    }
    float values[M::kPb];
    const char* p = action[1].c_str();
    for (int i = 0; i < M::kPb; ++i) {
      char* end = nullptr;
      values[i] = std::strtof(p, &end);
      if (end == p || (i + 1 < M::kPb ? *end != ',' : *end != '\0')) {
        std::fprintf(stderr, "hadynet link: pb '%s' is neither a state of the model nor %d comma-separated numbers\n",
                     action[1].c_str(), M::kPb);
        return 2;
      }
      p = end + 1;
    }
    session.set_pb(values);
    std::printf("%s: PB set (%d values)\n", stream.name().c_str(), M::kPb);
    return 0;
  }
  if (what == "adapt" && action.size() == 2) {
    link::AdaptRequest q;
    if (action[1] == "on") {
      q.action = link::AdaptAction::kOn;
    } else if (action[1] == "off") {
      q.action = link::AdaptAction::kOff;
    } else if (action[1] == "adopt") {
      q.action = link::AdaptAction::kAdopt;
    } else if (action[1] != "status") {
      std::fprintf(stderr, "hadynet link: adapt must be on, off, adopt or status\n");
      return 2;
    }
    const link::AdaptStatus<M> a = session.adapt(q);
    std::printf("%s: PB adaptation %s, %u steps (%u undone), %u windows held, stride %u, %u windows per period, "
                "loss %.4g\n",
                stream.name().c_str(), a.on ? "on" : "off", a.updates, a.rejected, a.windows, a.window_stride,
                a.windows_per_period, static_cast<double>(a.loss));
    const bool same_model = session.info().model_hash == M::kModelHash;
    const auto name = [&](std::uint16_t k) {
      return same_model && k < M::kStates ? std::string(M::kStateNames[k]) : "row " + std::to_string(k);
    };
    if (a.state != link::kNoState) {
      std::printf("nearest trained state %s (distance %.3g); nearest other object %s (%.3g)\n", name(a.state).c_str(),
                  static_cast<double>(a.distance),
                  a.other_state != link::kNoState ? name(a.other_state).c_str() : "-",
                  static_cast<double>(a.other_distance));
    }
    std::printf("adapted PB:");
    for (const float v : a.pb) std::printf(" %.4g", static_cast<double>(v));
    std::printf("\n");
    return 0;
  }
  std::fprintf(stderr, "hadynet link: unknown action (see --help)\n");
  return 2;
}

}  // namespace

int run_link(int argc, char** argv) {
  Options opt("link",
              "Talks to a device running the firmware over its serial link (docs/protocol.md). ACTION:\n"
              "  info                    the device's model hash, dims and versions (after a reset)\n"
              "  reset                   clear the history and the plan (mode and PB stay)\n"
              "  mode observe|detect|control\n"
              "  pb STATE|v1,..,vP       the active PB: a state of the PB table or standardised values\n"
              "  adapt on|off|adopt|status  the device's own PB adaptation (docs/firmware.md): on from the\n"
              "                          active PB, off, adopt (the adapted PB becomes the active one), or\n"
              "                          its status: steps, the adapted PB and the nearest trained states\n"
              "Every action first sends a reset, which also resynchronises the sequence numbers. To\n"
              "stream a log through the device use `hadynet replay LOG --target serial|tcp|qemu`.",
              "(--device PATH | --tcp HOST:PORT | --qemu ELF) ACTION [ARG]");
  opt.value("device", "PATH", "serial device (a USB-UART adapter, a pty)");
  opt.value("baud", "N", "baud rate of --device", "115200");
  opt.value("tcp", "HOST:PORT", "a socket (e.g. QEMU's -serial tcp:...)");
  opt.value("qemu", "ELF", "start QEMU with this firmware image and talk to it");
  opt.value("machine", "NAME", "QEMU machine for --qemu", "mps2-an386");
  opt.value("qemu-load", "FILE@ADDRESS",
            "with --qemu: place FILE's bytes at ADDRESS (e.g. 0x08080000) in the guest before it starts, such\n"
            "as a model slot's contents in the emulated flash");
  opt.value("numeric", "q15|f32", "the device's numeric (message sizes come from this build's model)", "q15");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (opt.positional().empty() || opt.has("device") + opt.has("tcp") + opt.has("qemu") != 1) {
    std::fprintf(stderr, "hadynet link: give one of --device, --tcp, --qemu and an ACTION (see --help)\n");
    return 2;
  }
  const auto parsed_numeric = opt.get_numeric("numeric");
  if (!parsed_numeric) return 2;
  try {
    std::unique_ptr<tools::QemuProcess> qemu;
    std::unique_ptr<tools::FdStream> own;
    tools::ByteStream* stream = nullptr;
    if (opt.has("qemu")) {
      tools::QemuOptions q{"qemu-system-arm", opt.get("machine"), opt.get("qemu"), false, "", {}};
      if (opt.has("qemu-load")) {
        const auto load = tools::parse_qemu_load(opt.get("qemu-load"));
        if (!load) {
          std::fprintf(stderr, "hadynet link: --qemu-load wants FILE@ADDRESS, got '%s'\n", opt.get("qemu-load").c_str());
          return 2;
        }
        q.loads.push_back(*load);
      }
      qemu = std::make_unique<tools::QemuProcess>(q);
      stream = &qemu->link();
    } else if (opt.has("device")) {
      const auto baud = opt.get_int("baud", 1, 10000000);
      if (!baud) return 2;
      own = std::make_unique<tools::FdStream>(tools::FdStream::open_serial(opt.get("device"), static_cast<int>(*baud)));
      stream = own.get();
    } else {
      const auto host_port = tools::parse_host_port(opt.get("tcp"));
      if (!host_port) {
        std::fprintf(stderr, "hadynet link: --tcp needs HOST:PORT, not '%s'\n", opt.get("tcp").c_str());
        return 2;
      }
      own = std::make_unique<tools::FdStream>(
          tools::FdStream::connect_tcp(host_port->first, host_port->second, 5000));
      stream = own.get();
    }
    return *parsed_numeric == firmware::Numeric::kQ15 ? act<model_q15::Model>(*stream, opt.positional())
                            : act<model_f32::Model>(*stream, opt.positional());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet link: %s\n", error_text(e).c_str());
    return 1;
  }
}

}  // namespace hadynet::cli
