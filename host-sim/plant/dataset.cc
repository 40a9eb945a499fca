#include "host-sim/plant/dataset.h"

#include <atomic>
#include <chrono>
#include <exception>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>

#include <mujoco/mujoco.h>

#include "datalog/atomic_file.h"
#include "datalog/log_writer.h"
#include "host-sim/plant/hand_geometry.h"

namespace hadynet::plant {

std::vector<ExperimentSpec> paper_preset(std::uint64_t seed, int steps) {
  std::vector<ExperimentSpec> specs;
  auto add = [&](ObjectKind object, int init, const char* split) {
    for (Motion motion : {Motion::kRandom1, Motion::kRandom2}) {
      ExperimentSpec s;
      s.object = object;
      s.motion = motion;
      s.init_id = init;
      s.steps = steps;
      s.seed = seed;
      s.split = split;
      specs.push_back(s);
    }
  };
  for (ObjectKind object : kPaperObjects)
    for (int init = 0; init < 3; ++init) add(object, init, "train");
  for (ObjectKind object : kPaperObjects) add(object, 3, "test");
  add(ObjectKind::kCylinderLarge, 3, "novel");
  return specs;
}

std::vector<ExperimentSpec> smoke_preset(std::uint64_t seed) {
  std::vector<ExperimentSpec> specs;
  for (ObjectKind object : {ObjectKind::kNone, ObjectKind::kCylinder})
    for (Motion motion : {Motion::kRandom1, Motion::kRandom2}) {
      ExperimentSpec s;
      s.object = object;
      s.motion = motion;
      s.steps = 60;
      s.seed = seed;
      specs.push_back(s);
    }
  return specs;
}

DatasetSummary collect_dataset(const std::vector<ExperimentSpec>& specs, const CollectOptions& options) {
  namespace fs = std::filesystem;
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  fs::create_directories(options.out_dir);

  std::vector<long> rows(specs.size(), 0), physics(specs.size(), 0);
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;  // guards done, first_error and the progress callback
  int done = 0;
  std::exception_ptr first_error;

  auto worker = [&] {
    while (!failed) {
      const std::size_t i = next++;
      if (i >= specs.size()) return;
      try {
        const ExperimentSpec& spec = specs[i];
        ExperimentResult result = run_experiment(spec);
        const fs::path dir = options.out_dir / spec.split;
        fs::create_directories(dir);
        datalog::write_log(dir / log_file_name(spec), result.log);
        rows[i] = static_cast<long>(result.log.rows());
        physics[i] = result.physics_steps;
        std::lock_guard lock(mutex);
        ++done;
        if (options.progress)
          options.progress(done, static_cast<int>(specs.size()), spec.split + "/" + log_file_name(spec), elapsed());
      } catch (...) {
        std::lock_guard lock(mutex);
        if (!first_error) first_error = std::current_exception();
        failed = true;
      }
    }
  };
  const int jobs = std::max(1, std::min<int>(options.jobs, static_cast<int>(specs.size())));
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  if (first_error) std::rethrow_exception(first_error);

  DatasetSummary summary;
  nlohmann::ordered_json manifest;
  manifest["format"] = "hadynet-dataset";
  manifest["format_version"] = 1;
  manifest["preset"] = options.preset;
  manifest["seed"] = options.seed;
  manifest["dt_s"] = geometry::kControlStep_s;
  manifest["plant"] = std::string("MuJoCo ") + mj_versionString() + ", host-sim/plant";
  auto& logs = manifest["logs"] = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const auto& s = specs[i];
    nlohmann::ordered_json entry;
    entry["file"] = s.split + "/" + log_file_name(s);
    entry["split"] = s.split;
    entry["state"] = state_id(s);
    entry["object"] = std::string(object_name(s.object));
    entry["motion"] = std::string(motion_name(s.motion));
    entry["init"] = s.init_id;
    entry["wear"] = s.wear_level;
    entry["rows"] = rows[i];
    if (s.declare_effects) entry["effects"] = s.effects.describe();
    logs.push_back(entry);
    summary.rows += rows[i];
    summary.physics_steps += physics[i];
  }
  const fs::path manifest_path = options.out_dir / "manifest.json";
  try {
    datalog::write_file_atomically(manifest_path, manifest.dump(2) + "\n");
  } catch (const datalog::AtomicWriteError& e) {
    throw std::runtime_error(std::string("cannot write the dataset manifest: ") + e.what());
  }
  summary.logs = static_cast<int>(specs.size());
  summary.wall_seconds = elapsed();
  return summary;
}

}  // namespace hadynet::plant
