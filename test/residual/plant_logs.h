// Plant logs for the residual tests: recorded from the MuJoCo hand on the fly
// (deterministic) in dynamics states the build's model was trained on (paper
// preset, seed 1, inits 0..2), with the plant's switchable effects switched on
// through ExperimentSpec::effects and declared nowhere in the logs.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "datalog/log_reader.h"
#include "host-sim/plant/experiment.h"
#include "trainer/model_file.h"
#include "trainer/residual/residuals.h"

namespace hadynet::test {

inline const trainer::HadynetModel& build_model() {
  static const trainer::HadynetModel model = trainer::load_model(HADYNET_MODEL_PATH);
  return model;
}

// The build model's stored held-out logs (rows of its training logs no
// training window used), as `hadynet residual` reads them for its default
// null. Rated ranges (with_rated_ranges) leave them as they are.
inline const std::vector<trainer::residual::LogInput>& stored_null() {
  static const std::vector<trainer::residual::LogInput> logs = [] {
    std::vector<trainer::residual::LogInput> out;
    for (const auto& stored : build_model().held_out_logs)
      out.push_back({datalog::parse_log(stored.text, "held-out log " + stored.name), stored.name});
    return out;
  }();
  return logs;
}

struct PlantLog {
  const char* object;  // plant name, e.g. "Cylinder"
  const char* motion;  // random1 | random2
  int init;            // a trained initialisation (0..2)
};

// The logs every effect test analyses: grasps of three objects (the loadcell
// effects need contact) and a Random-1 run, each `steps` rows.
inline const std::vector<PlantLog> kEffectLogs = {
    {"Cylinder", "random2", 1}, {"Ball", "random2", 2}, {"Gripper", "random2", 0}, {"Cylinder", "random1", 0}};

// The logs recorded with `effect` ("" for clean; plant syntax NAME[=VALUE]).
// Seed 1 is the model's training dataset seed; other seeds give fresh noise
// and motions in the same states (a state id decides its zeroing).
inline std::vector<trainer::residual::LogInput> plant_logs(const std::string& effect, int steps = 300,
                                                           std::uint64_t seed = 1) {
  std::vector<trainer::residual::LogInput> out;
  for (const auto& l : kEffectLogs) {
    plant::ExperimentSpec spec;
    spec.object = *plant::parse_object(l.object);
    spec.motion = *plant::parse_motion(l.motion);
    spec.init_id = l.init;
    spec.steps = steps;
    spec.seed = seed;
    if (!effect.empty()) {
      const std::string err = plant::apply_effect_arg(effect, spec.effects);
      if (!err.empty()) throw std::invalid_argument(err);
    }
    out.push_back({plant::run_experiment(spec).log, plant::log_file_name(spec)});
  }
  return out;
}

// The clean grasps of kEffectLogs recorded under another zeroing (init id
// `init` + the log's index, which the model never saw) and relabelled with
// the trained state names: a hand re-zeroed at start-up that keeps its names.
inline std::vector<trainer::residual::LogInput> rezeroed_plant_logs(int init, int steps = 300,
                                                                    std::uint64_t seed = 1) {
  std::vector<trainer::residual::LogInput> out;
  for (std::size_t i = 0; i < kEffectLogs.size(); ++i) {
    const auto& l = kEffectLogs[i];
    plant::ExperimentSpec spec;
    spec.object = *plant::parse_object(l.object);
    spec.motion = *plant::parse_motion(l.motion);
    spec.init_id = init + static_cast<int>(i);
    spec.steps = steps;
    spec.seed = seed;
    datalog::LogTable log = plant::run_experiment(spec).log;
    spec.init_id = l.init;
    log.metadata.set("state", plant::state_id(spec));
    out.push_back({std::move(log), plant::log_file_name(spec)});
  }
  return out;
}

}  // namespace hadynet::test
