// Collects a dataset: many experiments, run on all cores, written as logs in
// a folder with a manifest.json that lists every log with its split and
// dynamics state. Effects are listed in the manifest only when declared.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "host-sim/plant/experiment.h"

namespace hadynet::plant {

// The seed paper's dataset: 6 objects x {Random-1, Random-2} x 3
// initialisations x 500 steps ("train", about 18 000 windows), the same
// objects re-initialised ("test", initialisation 3) and the held-out
// Cylinder-L ("novel", initialisation 3).
std::vector<ExperimentSpec> paper_preset(std::uint64_t seed, int steps = 500);
// A small preset for smoke tests: 2 objects x 2 motions, 60 steps.
std::vector<ExperimentSpec> smoke_preset(std::uint64_t seed);

struct DatasetSummary {
  int logs = 0;
  long rows = 0;
  long physics_steps = 0;
  double wall_seconds = 0;
};

struct CollectOptions {
  std::filesystem::path out_dir;
  int jobs = 2;                  // worker threads
  std::string preset = "custom"; // recorded in the manifest
  std::uint64_t seed = 1;
  // Called after each log is written (from worker threads, serialised):
  // (logs done, logs total, file name, elapsed seconds).
  std::function<void(int, int, const std::string&, double)> progress;
};

// Runs every spec and writes <out_dir>/<split>/<file>.csv and
// <out_dir>/manifest.json (written last, atomically). Throws
// std::runtime_error on the first failure, after stopping the workers.
DatasetSummary collect_dataset(const std::vector<ExperimentSpec>& specs, const CollectOptions& options);

}  // namespace hadynet::plant
