// Held-out plant logs and the build's model for the firmware tests: the
// generated headers come from HADYNET_MODEL (codegen in the build); the same
// model is loaded at run time with the trainer as the double reference.
// The logs are recorded from the MuJoCo plant on the fly (deterministic):
// the paper preset's re-initialised test states (init 3, seed 1), which the
// model never trained on; None_random2 is also held out from the detection
// calibration (which used None_random1, scripts/paper_experiments.sh).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "host-sim/plant/experiment.h"
#include "trainer/log_dataset.h"
#include "trainer/model_file.h"

namespace hadynet::test {

inline const trainer::HadynetModel& build_model() {
  static const trainer::HadynetModel model = trainer::load_model(HADYNET_MODEL_PATH);
  return model;
}

// A held-out log of `object` (plant name, e.g. "Cylinder") with `motion`,
// init 3, seed 1, `steps` rows: the prefix of the paper preset's test log.
inline const datalog::LogTable& held_out_table(const std::string& object, const std::string& motion,
                                               int steps = 150) {
  static std::map<std::string, datalog::LogTable> cache;
  const std::string key = object + "/" + motion + "/" + std::to_string(steps);
  auto it = cache.find(key);
  if (it == cache.end()) {
    plant::ExperimentSpec spec;
    spec.object = plant::parse_object(object).value();
    spec.motion = plant::parse_motion(motion).value();
    spec.init_id = 3;
    spec.steps = steps;
    spec.seed = 1;
    spec.split = "test";
    it = cache.emplace(key, plant::run_experiment(spec).log).first;
  }
  return it->second;
}

inline trainer::LogSequence held_out_sequence(const std::string& object, const std::string& motion,
                                              int steps = 150) {
  return trainer::log_sequence(held_out_table(object, motion, steps), object + "_" + motion + "_i3",
                               build_model().layout);
}

}  // namespace hadynet::test
