// hadynet codegen and hadynet measure-ranges (docs/codegen.md): the command
// lines of codegen_command_line.h, with the trainer's network serving
// `codegen --logs`.
#include "cli/codegen_command_line.h"
#include "cli/commands.h"
#include "trainer/deploy_prep.h"

namespace hadynet::cli {

int run_codegen(int argc, char** argv) {
  return run_codegen_command("hadynet", "codegen", argc, argv, trainer::measure_log_ranges);
}

int run_measure_ranges(int argc, char** argv) {
  return run_measure_ranges_command("hadynet", "measure-ranges", argc, argv);
}

}  // namespace hadynet::cli
