// Build-time tool for the firmware tests of a model fixed by `hadynet
// residual --fix`: writes the build's model with every sensor-model part and
// derived inputs added, as --fix would (trainer/residual/augment.h), so that
// codegen and the firmware core are compiled and run against it.
//
//   make_fixed_model MODEL OUT
//
// Added: friction inputs sign_u0, hyst_u0 and, as for an absolute command,
// dsign_u1, dhyst_u1 (their LSTM input weights set to fixed non-zero values,
// so that the firmware's derived inputs matter), a 2-step dead time of the
// stabiliser command u3 (lag2_u3 takes u3's input weights, u3 none),
// cross-talk fc2 += 0.25 fc3, a load drift on fc3 (0.02 per N s, 0.2 s
// period), a calibration curve on fc3 (kFc3Curve) and a clip fc6 <= 2 N.
// No fine-tuning: the test compares the firmware with the trainer on this
// model, not the model with the plant.
// Value ranges are measured on two held-out plant logs in the model's frame.
#include <cmath>
#include <cstdio>
#include <exception>
#include <numeric>

#include "host-sim/plant/experiment.h"
#include "trainer/deploy_prep.h"
#include "trainer/model_file.h"
#include "trainer/residual/augment.h"
#include "trainer/window_dataset.h"

using namespace hadynet;
using namespace hadynet::trainer;

// fc3 reads g(level), g through (0, 0.05), (0.5, 0.6), (1.8, 1.6) N: an offset
// and a gain that falls with load. The held-out Cylinder grasp's fc3 (0 to
// 3 N) visits both segments and both continuations (below 0.05 N, above 1.6 N).
const SensorCurve kFc3Curve{"fc3", {0.0, 0.5, 1.8}, {0.05, 0.6, 1.6}};

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_fixed_model MODEL OUT\n");
    return 2;
  }
  try {
    const HadynetModel base = load_model(argv[1]);
    std::vector<residual::LogInput> logs;
    for (const char* object : {"Cylinder", "None"}) {
      plant::ExperimentSpec spec;
      spec.object = *plant::parse_object(object);
      spec.motion = *plant::parse_motion("random2");
      spec.init_id = 3;
      spec.steps = 150;
      spec.seed = 1;
      spec.split = "test";
      logs.push_back({plant::run_experiment(spec).log, std::string(object) + "_random2_i3"});
    }

    residual::Augmentation friction;
    friction.kind = residual::EffectKind::kFriction;
    friction.effect = "friction";
    friction.description = "test: hysteresis inputs of u0 and of u1's change, u3 two steps earlier";
    friction.change.emplace<residual::DerivedCommandInputs>().inputs = {"sign_u0", "hyst_u0", "dsign_u1", "dhyst_u1",
                                                                        "lag2_u3"};
    std::vector<LogSequence> seqs;
    const FeatureLayout layout = residual::augmented_layout(base.layout, friction);
    for (const auto& l : logs) seqs.push_back(log_sequence(l.table, l.file, layout));
    HadynetModel m = residual::augmented_model(base, friction, seqs);
    // Fixed, non-zero weights for the four friction inputs (columns before
    // the PB). u3 acts only through its dead time: augmented_model already
    // moved u3's column to lag2_u3 (the fix's pure dead-time start).
    auto& ih = m.params.lstm_weight_ih;
    const int u_old = base.params.dims.u;
    for (Eigen::Index r = 0; r < ih.rows(); ++r)
      for (int k = 0; k < 4; ++k)
        ih(r, u_old + k) = 0.05f * static_cast<float>(std::sin(0.37 * static_cast<double>(r) + k));
    if (ih.col(3).norm() != 0.0f || ih.col(u_old + 4).norm() == 0.0f) {
      std::fprintf(stderr, "make_fixed_model: lag2_u3 did not take u3's input weights\n");
      return 1;
    }

    m.sensor.crosstalk = {{"fc2", "fc3", 0.25}};
    m.sensor.drifts = {{"fc3", true, 0.02}};
    m.sensor.period_s = 0.2;
    m.sensor.curves = {kFc3Curve};
    // fc6 a rail (a plain channel); fc2 (a cross-talk target) its rated
    // floor at 0 N, which bounds only what it reports (frame_rail: none on
    // the network's channel).
    m.sensor.clips = {{"fc6", 1, 2.0}, {"fc2", -1, 0.0}};
    m.provenance["residual_fix"] = "test model of test/firmware/make_fixed_model.cc (no fine-tuning)";
    m.check_consistent();

    std::vector<LogSequence> frame;
    for (const auto& l : logs) frame.push_back(log_sequence(to_model_frame(m.sensor, l.table, l.file), l.file, m.layout));
    const WindowDataset data(frame, {0, 0}, m.layout, m.norm, m.train_steps);
    std::vector<int> ids(static_cast<std::size_t>(data.size()));
    std::iota(ids.begin(), ids.end(), 0);
    ValueRanges ranges = measure_ranges(m, data, ids);
    ranges.source = "make_fixed_model: 2 held-out plant logs in the model's frame";
    m.ranges = ranges;
    save_model(argv[2], m);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_fixed_model: %s\n", e.what());
    return 1;
  }
}
