// --threads N of the PB and residual subcommands (adapt, recognize,
// calibrate-detect, residual; train has its own, every core by default): how
// many threads run the network's forward and backward passes (trainer::training_pool(), trainer/work_pool.h).
// Results are the same bytes at any count (hadynet_network.h).
#pragma once

#include <string>

#include "cli/options.h"

namespace hadynet::cli {

// Adds --threads N with `default_threads` ("0": every core).
void add_threads_option(Options& opt, const std::string& default_threads);

// Sets the pool from --threads and, when it has more than one thread, says
// so on stderr ("hadynet COMMAND: the network's passes on N threads").
// False, after get_int's message, when the value is not 0..1024.
bool apply_threads_option(const Options& opt, const std::string& command);

}  // namespace hadynet::cli
