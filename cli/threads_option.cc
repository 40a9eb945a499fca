#include "cli/threads_option.h"

#include <cstdio>

#include "trainer/work_pool.h"

namespace hadynet::cli {

void add_threads_option(Options& opt, const std::string& default_threads) {
  opt.value("threads", "N",
            "threads of the network's forward and backward passes (0: every core); results do not\n"
            "depend on it",
            default_threads);
}

bool apply_threads_option(const Options& opt, const std::string& command) {
  const auto threads = opt.get_int("threads", 0, 1024);
  if (!threads) return false;
  trainer::set_training_threads(static_cast<int>(*threads));
  const int used = trainer::training_pool().threads();
  if (used > 1) std::fprintf(stderr, "hadynet %s: the network's passes on %d threads\n", command.c_str(), used);
  return true;
}

}  // namespace hadynet::cli
