// hadynet: one program, one subcommand per job (kCommands below).
#include <cstdio>
#include <cstring>

#include "cli/commands.h"
#include "cli/error_text.h"

namespace {

struct Command {
  const char* name;
  const char* summary;
  int (*run)(int, char**);
};

constexpr Command kCommands[] = {
    {"collect", "record logs from the MuJoCo hand plant (a preset dataset or one experiment)",
     hadynet::cli::run_collect},
    {"validate", "check logs or a dataset folder strictly and print a summary", hadynet::cli::run_validate},
    {"import", "a plain column CSV (measured data from anywhere) -> a HADYNET log", hadynet::cli::run_import},
    {"plot", "draw a log as a PNG (gnuplot): one panel per channel group", hadynet::cli::run_plot},
    {"train", "train HADYNET and the PB table from logs; write a model file", hadynet::cli::run_train},
    {"adapt", "fit the PB alone to new logs (offline, or --online over a stream)", hadynet::cli::run_adapt},
    {"recognize", "adapt the PB, name the nearest trained state's object, plot the PB map",
     hadynet::cli::run_recognize},
    {"calibrate-detect", "contact-detection statistics and threshold from contact-free logs",
     hadynet::cli::run_calibrate_detect},
    {"detect", "contact detection over logs: d per step, flags, traces plot", hadynet::cli::run_detect},
    {"residual", "the model's residuals, residual tests and the effect it lacks (report, JSON)", hadynet::cli::run_residual},
    {"simulate", "predict a log from a start state, commands and any PB (contact simulation)",
     hadynet::cli::run_simulate},
    {"measure-ranges", "measure the value ranges codegen needs and store them in the model",
     hadynet::cli::run_measure_ranges},
    {"codegen", "generate the firmware's C++ model header (q15 fixed point or f32)",
     hadynet::cli::run_codegen},
    {"keygen", "an Ed25519 key pair for signing model images", hadynet::cli::run_keygen},
    {"model-image", "a trained model -> a signed model image for this build's firmware (model slots)",
     hadynet::cli::run_model_image},
    {"replay", "host-sim: replay a log through the firmware core (prediction, d, contact, command)",
     hadynet::cli::run_replay},
    {"link", "talk to a device running the firmware over its serial link (info, reset, mode, pb)",
     hadynet::cli::run_link},
    {"devices", "list the HADYNET MCUs on USB (serial, firmware, model hash) and STM32 ROM bootloaders",
     hadynet::cli::run_devices},
    {"monitor", "the MCU's telemetry over USB: a line per period, drops counted, logs and a plot",
     hadynet::cli::run_monitor},
    {"flash", "firmware (or --model a model) into the MCU over USB: erase, write, read back, verify",
     hadynet::cli::run_flash},
    {"stabilize",
     "host-sim: the grasp stabiliser in closed loop with the MuJoCo hand under a scripted disturbance (E with/without)",
     hadynet::cli::run_stabilize},
};

void print_help() {
  std::puts("usage: hadynet COMMAND [options]   (hadynet COMMAND --help for a command's options)\n");
  std::puts("HADYNET: a learned dynamics model with parametric bias for a flexible tendon-driven hand.\n");
  std::puts("commands:");
  for (const auto& c : kCommands) std::printf("  %-17s %s\n", c.name, c.summary);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    print_help();
    return argc < 2 ? 2 : 0;
  }
  for (const auto& c : kCommands) {
    if (std::strcmp(argv[1], c.name) != 0) continue;
    // Commands report their own errors; this catches what one lets escape,
    // so no input ever ends in std::terminate or an exception's bare text.
    try {
      return c.run(argc - 2, argv + 2);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "hadynet %s: %s\n", c.name, hadynet::cli::error_text(e).c_str());
      return 1;
    }
  }
  std::fprintf(stderr, "hadynet: unknown command '%s' (see hadynet --help)\n", argv[1]);
  return 2;
}
