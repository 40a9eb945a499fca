// Build-time tool for link_fuzzer_tiny (docs/protocol.md, "Fuzzing"): the
// build's model with its channels, normalisation, PB table, detection
// statistics and hyper-parameters kept, and the network shrunk to 4 LSTM
// units. Codegen turns it into a header with the same contract, the same
// message sizes and the same code paths (observe, detect, control with the
// stabiliser's BPTT and line search) as the real model, at about 1/100 of
// a control period's cost, so the link fuzzer runs thousands of inputs per
// second. Value ranges are measured on one held-out plant log.
//
//   make_tiny_model MODEL OUT
#include <cstdio>
#include <exception>
#include <numeric>

#include "host-sim/plant/experiment.h"
#include "trainer/deploy_prep.h"
#include "trainer/model_file.h"
#include "trainer/training.h"
#include "trainer/window_dataset.h"

using namespace hadynet;
using namespace hadynet::trainer;

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_tiny_model MODEL OUT\n");
    return 2;
  }
  try {
    constexpr int kTinyHidden = 4;
    const HadynetModel base = load_model(argv[1]);
    HadynetModel tiny = new_model(base.layout, base.norm, base.states, base.params.dims.pb, kTinyHidden,
                                  base.train_steps, /*seed=*/5);
    tiny.params.pb = base.params.pb;
    tiny.detection = base.detection;
    tiny.sensor = base.sensor;
    tiny.profile = base.profile;
    tiny.period_s = base.period_s;
    tiny.hyper_parameters = base.hyper_parameters;
    tiny.provenance = {{"source", "fuzz/make_tiny_model.cc: " + std::string(argv[1]) + " with 4 LSTM units, untrained"}};

    plant::ExperimentSpec spec;
    spec.object = *plant::parse_object("Cylinder");
    spec.motion = *plant::parse_motion("random2");
    spec.init_id = 3;
    spec.steps = 60;
    spec.seed = 1;
    spec.split = "test";
    const LogSequence seq = log_sequence(plant::run_experiment(spec).log, "Cylinder_random2_i3", tiny.layout);
    const WindowDataset data({seq}, {0}, tiny.layout, tiny.norm, tiny.train_steps);
    std::vector<int> ids(static_cast<std::size_t>(data.size()));
    std::iota(ids.begin(), ids.end(), 0);
    ValueRanges ranges = measure_ranges(tiny, data, ids);
    ranges.source = "make_tiny_model: one held-out plant log";
    tiny.ranges = ranges;
    tiny.check_consistent();
    save_model(argv[2], tiny);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_tiny_model: %s\n", e.what());
    return 1;
  }
}
