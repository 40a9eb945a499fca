// hadynet-codegen: the codegen command alone (the same options as
// `hadynet codegen`), so the build can generate the model headers without
// building the whole hadynet program (docs/codegen.md); and
// `hadynet-codegen measure-ranges ...` (as `hadynet measure-ranges`).
#include <cstring>

#include "codegen/codegen_command.h"

int main(int argc, char** argv) {
  if (argc >= 2 && std::strcmp(argv[1], "measure-ranges") == 0) {
    return hadynet::codegen::run_measure_ranges_command("hadynet-codegen", argc - 2, argv + 2);
  }
  return hadynet::codegen::run_codegen_command("hadynet-codegen", "", argc - 1, argv + 1);
}
