// hadynet-measure-ranges: `hadynet measure-ranges` alone, so that a model
// file without value ranges can be prepared for codegen without building the
// whole hadynet program, which includes the generated model (docs/codegen.md).
#include "cli/codegen_command_line.h"

int main(int argc, char** argv) {
  return hadynet::cli::run_measure_ranges_command("hadynet-measure-ranges", "", argc - 1, argv + 1);
}
