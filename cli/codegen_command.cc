// hadynet codegen and hadynet measure-ranges (docs/codegen.md). The commands
// live in codegen/ (codegen_command.h), shared with the standalone
// hadynet-codegen the build runs.
#include "cli/commands.h"
#include "codegen/codegen_command.h"

namespace hadynet::cli {

int run_codegen(int argc, char** argv) {
  return codegen::run_codegen_command("hadynet", "codegen", argc, argv);
}

int run_measure_ranges(int argc, char** argv) {
  return codegen::run_measure_ranges_command("hadynet", argc, argv);
}

}  // namespace hadynet::cli
