// measure-ranges (`hadynet measure-ranges`, `hadynet-measure-ranges`): the value ranges of every tensor the firmware
// computes (trainer/deploy_prep.h), measured over every window of the given
// logs and stored in the model file, from which codegen picks the fixed-point
// formats (docs/codegen.md). `hadynet train` stores them already; this
// command adds them to older models or re-measures them on other logs.
#include <cstdio>
#include <stdexcept>

#include "cli/codegen_command_line.h"
#include "cli/options.h"
#include "trainer/deploy_prep.h"
#include "trainer/model_file.h"

namespace hadynet::cli {

int run_measure_ranges_command(const std::string& program, const std::string& command, int argc, char** argv) {
  Options opt(command,
              "Measures the largest absolute value of the inputs, encoder, LSTM gates, cell and hidden\n"
              "states and outputs (standardised units, BN in eval mode) over every N_train-step window of\n"
              "the logs, each log with its state's PB (its metadata 'state' must be in the model's PB\n"
              "table), and of the weights and biases; prints them and stores them in the model file\n"
              "(metadata 'ranges', docs/model-file.md). Rewrites MODEL atomically unless --out is given.",
              "MODEL LOG|DIR... [--out MODEL]", program);
  opt.value("out", "MODEL", "model file to write instead of rewriting MODEL");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  const std::string who = command.empty() ? program : program + " " + command;
  if (opt.positional().size() < 2) {
    std::fprintf(stderr, "%s: give MODEL and logs or folders (see --help)\n", who.c_str());
    return 2;
  }
  const std::string model_path = opt.positional().front();
  const std::string out = opt.has("out") ? opt.get("out") : model_path;
  try {
    trainer::HadynetModel model = trainer::load_model(model_path);
    const std::vector<std::string> logs(opt.positional().begin() + 1, opt.positional().end());
    const trainer::ValueRanges r = trainer::measure_log_ranges(model, logs);
    std::printf("value ranges (max |v|, standardised units) from %s; %ld windows\n",
                r.source.c_str(), r.windows);
    for (const trainer::ValueRangeField& f : trainer::kValueRangeFields)
      std::printf("  %-12s %10.5f\n", f.name, r.*f.member);
    model.ranges = r;
    trainer::save_model(out, model);
    std::printf("wrote %s\n", out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", who.c_str(), e.what());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
