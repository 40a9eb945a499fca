#include "cli/codegen_command_line.h"

#include <charconv>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "cli/options.h"
#include "codegen/codegen.h"
#include "datalog/robot_profile.h"

namespace hadynet::cli {

using namespace codegen;

namespace {

// "1,0.5,0.25" -> numbers; nullopt (after a message) on a malformed list.
std::optional<std::vector<double>> parse_alphas(const std::string& text, const std::string& who) {
  std::vector<double> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    double v = 0;
    const auto [p, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (item.empty() || ec != std::errc() || p != item.data() + item.size()) {
      std::fprintf(stderr, "%s: --control-alphas: '%s' is not a comma-separated list of numbers\n",
                   who.c_str(), text.c_str());
      return std::nullopt;
    }
    out.push_back(v);
    if (end == text.size()) break;
    start = end + 1;
  }
  return out;
}

void print_formats(const Formats& f) {
  const std::pair<const char*, const FormatChoice*> rows[] = {
      {"kFracIn", &f.in},         {"kFracH", &f.h},           {"kFracC", &f.c},
      {"kFracY", &f.y},           {"kFracGate", &f.gate},     {"kFracEncW", &f.enc_w},
      {"kFracLstmW", &f.lstm_w},  {"kFracLstmAcc", &f.lstm_acc}, {"kFracDecW", &f.dec_w},
      {"kFracWhiten", &f.whiten}, {"kFracZ", &f.z},           {"kFracLossW", &f.loss_w}};
  for (const auto& [name, c] : rows) std::printf("  %-13s Q%-2d  %s\n", name, c->frac, c->from.c_str());
}

}  // namespace

void add_model_options(cli::Options& opt) {
  opt.value("headroom", "H", "factor on the measured activation ranges before choosing formats", "1.5");
  opt.value("control-horizon", "N", "grasp stabiliser horizon N_control (<= the model's N_train)", "8");
  opt.value("control-epochs", "N", "gradient steps per control period (N_epoch)", "3");
  opt.value("control-alphas", "LIST", "step sizes tried per gradient step (N_batch of them)",
            "1,0.5,0.25,0.125");
  opt.value("control-truncation", "K", "BPTT truncation depth (>= horizon: full; default: the horizon)");
  opt.value("beta", "B", "force loss weight where the estimate is below the reference", "3");
  opt.value("w2", "W", "wrist angle loss weight", "1");
  opt.value("w3", "W", "muscle length loss weight", "1");
  opt.value("loss-units", "physical|standardised",
            "units of the stabiliser's loss: physical (the paper's raw values; weights x std^2) or "
            "standardised", "physical");
  opt.value("control-commands", "NAMES|all|profile",
            "u channels the stabiliser may change, comma-separated (others stay at 'no change'); profile:\n"
            "the model's robot profile (the logs' control_commands; all when they name none)", "profile");
  opt.value("force-groups", "GROUPS|none|profile", "y groups in the stabiliser's force loss class (profile: the model's)",
            "profile");
  opt.value("angle-groups", "GROUPS|none|profile", "y groups in its angle loss class (profile: the model's)", "profile");
  opt.value("length-groups", "GROUPS|none|profile", "y groups in its length loss class (profile: the model's)",
            "profile");
  opt.value("period-s", "S",
            "the control period (s) for a model file that does not record it (trained before model files\n"
            "stored the logs' dt_s); a model that records its period must not be given another");
}

bool read_model_options(const cli::Options& opt, const std::string& who, CodegenOptions& options) {
  const auto headroom = opt.get_double("headroom", 1.0, 1e6);
  const auto horizon = opt.get_int("control-horizon", 1, 100000);
  const auto epochs = opt.get_int("control-epochs", 1, 100000);
  const auto alphas = parse_alphas(opt.get("control-alphas"), who);
  std::optional<long long> truncation;
  if (opt.has("control-truncation")) {
    truncation = opt.get_int("control-truncation", 1, 100000);
    if (!truncation) return false;
  }
  const auto beta = opt.get_double("beta", 0.0, 1e6);
  const auto w2 = opt.get_double("w2", 0.0, 1e6);
  const auto w3 = opt.get_double("w3", 0.0, 1e6);
  if (!headroom || !horizon || !epochs || !alphas || !beta || !w2 || !w3) return false;
  if (opt.has("period-s")) {
    const auto period = opt.get_double("period-s", 1e-6, 4294.0);
    if (!period) return false;
    options.period_s = *period;
  }
  options.headroom = *headroom;
  options.control.horizon = static_cast<int>(*horizon);
  options.control.epochs = static_cast<int>(*epochs);
  options.control.alphas = *alphas;
  if (truncation) options.control.truncation = static_cast<int>(*truncation);
  options.control.loss.beta = *beta;
  options.control.loss.w2 = *w2;
  options.control.loss.w3 = *w3;
  if (opt.get("loss-units") == "physical") {
    options.control.loss.physical_units = true;
  } else if (opt.get("loss-units") == "standardised") {
    options.control.loss.physical_units = false;
  } else {
    std::fprintf(stderr, "%s: --loss-units must be physical or standardised, got '%s'\n", who.c_str(),
                 opt.get("loss-units").c_str());
    return false;
  }
  // Lists that default to the model's robot profile (datalog/robot_profile.h).
  const auto profile_list = [&](const char* name, const char* all_word,
                                std::optional<std::vector<std::string>>& out) {
    const std::string text = opt.get(name);
    if (text == "profile") return true;
    if (text == all_word) {
      out.emplace();
      return true;
    }
    try {
      out = datalog::split_list(text);
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "%s: --%s: %s\n", who.c_str(), name, e.what());
      return false;
    }
    return true;
  };
  if (!profile_list("control-commands", "all", options.control.commands) ||
      !profile_list("force-groups", "none", options.control.force_groups) ||
      !profile_list("angle-groups", "none", options.control.angle_groups) ||
      !profile_list("length-groups", "none", options.control.length_groups)) {
    return false;
  }

  return true;
}

int run_codegen_command(const std::string& program, const std::string& command, int argc, char** argv,
                        const RangeMeasure& measure) {
  cli::Options opt(
      command,
      "Generates one allocation-free C++ header from a trained model file: every constant and\n"
      "array of the firmware contract (firmware/core/model_contract.h) as static constexpr members\n"
      "of `struct Model`, in fixed point (q15: int16 values in per-tensor Q formats chosen from the\n"
      "model's measured value ranges, int32 biases) or float32 (f32). Writes\n"
      "DIR/hadynet_model_<numeric>.h atomically; an unsupported model is rejected before anything\n"
      "is written (docs/codegen.md). --logs: measure the value ranges on the logs given after MODEL\n"
      "instead of using those stored in the model (hadynet codegen only; hadynet-codegen uses the\n"
      "stored ranges, so that its output is the same on every machine).",
      "MODEL --numeric q15|f32 --out DIR [options] [--logs LOG|DIR...]", program);
  opt.value("numeric", "q15|f32", "number format of the generated model");
  opt.value("out", "DIR", "directory to write hadynet_model_<numeric>.h into (created if needed)");
  opt.value("namespace", "NS", "C++ namespace (default: hadynet::model_q15 / hadynet::model_f32)");
  add_model_options(opt);
  opt.flag("logs", "measure the value ranges on the logs/folders given after MODEL");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  const std::string who = command.empty() ? program : program + " " + command;
  const bool with_logs = opt.has("logs");
  if (opt.positional().empty() || !opt.has("numeric") || !opt.has("out")) {
    std::fprintf(stderr, "%s: give MODEL, --numeric and --out (see --help)\n", who.c_str());
    return 2;
  }
  if (with_logs != (opt.positional().size() > 1)) {
    std::fprintf(stderr, "%s: %s\n", who.c_str(),
                 with_logs ? "--logs needs logs or folders after MODEL"
                           : "give one MODEL (logs after it only with --logs)");
    return 2;
  }
  if (with_logs && !measure) {
    std::fprintf(stderr,
                 "%s: --logs runs the trainer's network, which this tool does not link (its output must be\n"
                 "the same bytes on every machine): store the ranges with hadynet-measure-ranges or\n"
                 "`hadynet measure-ranges` first, or use `hadynet codegen --logs`\n",
                 who.c_str());
    return 2;
  }
  CodegenOptions options;
  if (const auto numeric = opt.get_numeric("numeric")) {
    options.numeric = *numeric;
  } else {
    return 2;
  }
  options.ns = opt.get("namespace");
  if (!read_model_options(opt, who, options)) return 2;

  const std::string model_path = opt.positional().front();
  try {
    LoadedModel loaded = load_model_file(model_path);
    if (with_logs) {
      const std::vector<std::string> logs(opt.positional().begin() + 1, opt.positional().end());
      loaded.model.ranges = measure(loaded.model, logs);
      std::printf("value ranges measured on %s\n", loaded.model.ranges->source.c_str());
    }
    GeneratedHeader header;
    try {
      header = generate(loaded.model, loaded.identity, options);
    } catch (const UnsupportedModel& e) {
      throw std::runtime_error(model_path + ": unsupported model: " + e.what());
    }
    const WriteResult written = write_header(opt.get("out"), header);
    std::printf("%s: %s model %s (%s)\n", written.path.c_str(), numeric_name(options.numeric),
                namespace_of(options).c_str(), written.changed ? "written" : "unchanged");
    if (options.numeric == Numeric::kQ15) print_formats(header.formats);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", who.c_str(), e.what());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
