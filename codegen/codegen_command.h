// The codegen and measure-ranges command lines, shared by `hadynet codegen`,
// `hadynet measure-ranges` and the standalone `hadynet-codegen` the build
// runs (docs/codegen.md). The standalone tool has measure-ranges too, so that
// a model without ranges can be prepared without building the whole hadynet
// program (which includes the generated model).
#pragma once

#include <string>

namespace hadynet::codegen {

// Parses the options after the program (or subcommand) name, loads MODEL,
// generates the header and writes it to --out atomically. `program` names the
// caller in messages ("hadynet", "hadynet-codegen"), `command` the
// subcommand ("codegen", or "" for the standalone tool). Returns the exit
// code: 0 ok, 1 failure (unreadable or unsupported model: nothing written),
// 2 usage error.
int run_codegen_command(const std::string& program, const std::string& command, int argc,
                        char** argv);

// Measures the value ranges of MODEL on logs and stores them in the model
// file (trainer::measure_log_ranges); options after "measure-ranges".
int run_measure_ranges_command(const std::string& program, int argc, char** argv);

}  // namespace hadynet::codegen
