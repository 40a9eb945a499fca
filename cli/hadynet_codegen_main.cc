// hadynet-codegen: the codegen command alone (the options of `hadynet
// codegen` without --logs), built from portable code only, so the build can
// generate the model headers without building the whole hadynet program and
// every machine writes the same bytes (docs/codegen.md).
#include "cli/codegen_command_line.h"

int main(int argc, char** argv) {
  return hadynet::cli::run_codegen_command("hadynet-codegen", "", argc - 1, argv + 1, {});
}
