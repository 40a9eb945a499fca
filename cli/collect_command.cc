// hadynet collect: record logs from the MuJoCo hand plant.
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/options.h"
#include "host-sim/plant/dataset.h"

namespace hadynet::cli {

int run_collect(int argc, char** argv) {
  Options opt("collect",
              "Records logs (docs/log-format.md) from the MuJoCo model of the flexible hand. With --preset it\n"
              "records a whole dataset (paper: 6 objects x Random-1/Random-2 x 3 initialisations x 500 steps\n"
              "for training, the objects re-initialised for testing, and the held-out Cylinder-L), else one\n"
              "experiment given by --object/--motion/--init/--wear. Writes OUT/<split>/*.csv and\n"
              "OUT/manifest.json. Deterministic for a seed, whatever --jobs is.",
              "--out DIR [--preset paper|smoke | --object NAME --motion random1|random2 ...]");
  opt.value("out", "DIR", "output folder (created)");
  opt.value("preset", "NAME", "paper | smoke: record a whole dataset");
  opt.value("seed", "N", "dataset seed", "1");
  opt.value("jobs", "N", "worker threads", std::to_string(std::max(1u, std::thread::hardware_concurrency())));
  opt.value("rows", "N", "rows (control periods, 0.2 s each) per log", "500");
  opt.value("object", "NAME", plant::object_list(), "None");
  opt.value("motion", "NAME", "random1 | random2", "random1");
  opt.value("init", "N", "initialisation (encoder zeroing) id", "0");
  opt.value("wear", "W", "wear level, 0 (new) .. 1 (worn)", "0");
  opt.value("split", "NAME", "split folder for a single experiment", "train");
  opt.repeated("effect", "NAME[=V]", plant::effect_arg_help("                          "));
  opt.flag("declare-effects", "write the switched-on effects into the logs and manifest (default: undeclared)");
  opt.flag("no-realism", "no sensor noise, quantisation or rated ranges");
  opt.flag("quiet", "no progress output");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (!opt.positional().empty()) {
    std::fprintf(stderr, "hadynet collect: unexpected argument '%s'\n", opt.positional().front().c_str());
    return 2;
  }
  if (!opt.has("out")) {
    std::fprintf(stderr, "hadynet collect: --out DIR is required\n");
    return 2;
  }
  const auto seed = opt.get_int("seed", 0, (1ll << 62));
  const auto jobs = opt.get_int("jobs", 1, 256);
  const auto steps = opt.get_int("rows", 11, 1000000);
  const auto init = opt.get_int("init", 0, 1000000);
  const auto wear = opt.get_double("wear", 0.0, 1.0);
  if (!seed || !jobs || !steps || !init || !wear) return 2;

  plant::Effects effects;
  for (const auto& e : opt.all("effect")) {
    if (const std::string err = plant::apply_effect_arg(e, effects); !err.empty()) {
      std::fprintf(stderr, "hadynet collect: %s\n", err.c_str());
      return 2;
    }
  }

  std::vector<plant::ExperimentSpec> specs;
  const std::string preset = opt.get("preset");
  if (preset == "paper") {
    specs = plant::paper_preset(static_cast<std::uint64_t>(*seed), static_cast<int>(*steps));
  } else if (preset == "smoke") {
    specs = plant::smoke_preset(static_cast<std::uint64_t>(*seed));
  } else if (!preset.empty()) {
    std::fprintf(stderr, "hadynet collect: unknown preset '%s' (expected paper or smoke)\n", preset.c_str());
    return 2;
  } else {
    plant::ExperimentSpec s;
    const auto object = plant::parse_object(opt.get("object"));
    const auto motion = plant::parse_motion(opt.get("motion"));
    if (!object) {
      std::fprintf(stderr, "hadynet collect: --object: unknown object '%s'\n", opt.get("object").c_str());
      return 2;
    }
    if (!motion) {
      std::fprintf(stderr, "hadynet collect: --motion: expected random1 or random2, got '%s'\n",
                   opt.get("motion").c_str());
      return 2;
    }
    s.object = *object;
    s.motion = *motion;
    s.init_id = static_cast<int>(*init);
    s.wear_level = *wear;
    s.steps = static_cast<int>(*steps);
    s.seed = static_cast<std::uint64_t>(*seed);
    s.split = opt.get("split");
    specs.push_back(s);
  }
  for (auto& s : specs) {
    s.effects = effects;
    s.declare_effects = opt.has("declare-effects");
    s.sensor_realism = !opt.has("no-realism");
  }

  plant::CollectOptions options;
  options.out_dir = opt.get("out");
  options.jobs = static_cast<int>(*jobs);
  options.preset = preset.empty() ? "single" : preset;
  options.seed = static_cast<std::uint64_t>(*seed);
  if (!opt.has("quiet")) {
    options.progress = [](int done, int total, const std::string& file, double elapsed_s) {
      const double eta_s = elapsed_s / done * (total - done);
      std::fprintf(stderr, "\r[%3d/%d] %-40s %5.1f s elapsed, ETA %5.1f s", done, total, file.c_str(), elapsed_s,
                   eta_s);
      if (done == total) std::fputc('\n', stderr);
      std::fflush(stderr);
    };
  }
  try {
    const auto summary = plant::collect_dataset(specs, options);
    std::printf("collected %d logs, %ld rows, %ld physics steps in %.1f s (%.0f physics steps/s) into %s\n",
                summary.logs, summary.rows, summary.physics_steps, summary.wall_seconds,
                static_cast<double>(summary.physics_steps) / std::max(summary.wall_seconds, 1e-9), options.out_dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nhadynet collect: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
