// hadynet: one program, one subcommand per job (collect, validate, and the
// trainer, codegen and replay commands as they land).
#include <cstdio>
#include <cstring>

#include "cli/commands.h"

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
    {"plot", "draw a log as a PNG (gnuplot): one panel per channel group", hadynet::cli::run_plot},
};

void print_help() {
  std::puts("usage: hadynet COMMAND [options]   (hadynet COMMAND --help for a command's options)\n");
  std::puts("HADYNET: a learned dynamics model with parametric bias for a flexible tendon-driven hand.\n");
  std::puts("commands:");
  for (const auto& c : kCommands) std::printf("  %-10s %s\n", c.name, c.summary);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    print_help();
    return argc < 2 ? 2 : 0;
  }
  for (const auto& c : kCommands)
    if (std::strcmp(argv[1], c.name) == 0) return c.run(argc - 2, argv + 2);
  std::fprintf(stderr, "hadynet: unknown command '%s' (see hadynet --help)\n", argv[1]);
  return 2;
}
