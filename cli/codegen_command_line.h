// The codegen and measure-ranges command lines (docs/codegen.md), shared by
// `hadynet codegen|measure-ranges` and the two standalone tools the build
// runs: hadynet-codegen, built from portable code only (no -march=native, no
// trainer), so that the headers it writes are the same bytes on every
// x86-64, and hadynet-measure-ranges, which needs the trainer's network (a
// model without ranges can be prepared without building the whole hadynet
// program, which includes the generated model).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "cli/options.h"
#include "codegen/codegen_options.h"
#include "trainer/hadynet_model.h"

namespace hadynet::cli {

// Measures a model's value ranges on logs or folders
// (trainer::measure_log_ranges); how `codegen --logs` is served.
using RangeMeasure =
    std::function<trainer::ValueRanges(const trainer::HadynetModel& model, const std::vector<std::string>& logs)>;

// Parses the options after the program (or subcommand) name, loads MODEL,
// generates the header and writes it to --out atomically. `program` names the
// caller in messages ("hadynet", "hadynet-codegen"), `command` the
// subcommand ("codegen", or "" for the standalone tool). `measure` serves
// --logs; empty: --logs is a usage error that names the tools that have it.
// Returns the exit code: 0 ok, 1 failure (unreadable or unsupported model:
// nothing written), 2 usage error.
int run_codegen_command(const std::string& program, const std::string& command, int argc, char** argv,
                        const RangeMeasure& measure);

// The options that shape a generated header beyond its numeric and namespace
// (headroom, the stabiliser's constants and loss, its commands and loss
// groups, the period), declared on `opt` and read back into `options`:
// codegen and model-image (an image must be generated with the options its
// firmware's header was). read_model_options prints what is wrong and
// returns false on a usage error.
void add_model_options(cli::Options& opt);
bool read_model_options(const cli::Options& opt, const std::string& who, codegen::CodegenOptions& options);

// Measures the value ranges of MODEL on logs and stores them in the model
// file (trainer::measure_log_ranges); the options after "measure-ranges"
// (`command` "measure-ranges", or "" for the standalone tool).
int run_measure_ranges_command(const std::string& program, const std::string& command, int argc, char** argv);

}  // namespace hadynet::cli
