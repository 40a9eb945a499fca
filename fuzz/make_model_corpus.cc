// Writes the seed corpus of model_fuzzer (fuzz/corpus/model): small model
// files that exercise every part of the reader: a model with detection
// statistics, value ranges, a sensor model (delay, cross-talk, drift,
// calibration curve: format_version 2, clip) and held-out logs, and a bare
// one (format_version 1). Small (a few KiB) so that the fuzzer mutates them
// thousands of times per second; the hand's 0.36 MiB model is read by the
// reader's unit tests.
//   make_model_corpus OUT_DIR
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "trainer/log_dataset.h"
#include "trainer/model_file.h"
#include "trainer/normalization.h"
#include "trainer/training.h"

namespace tr = hadynet::trainer;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_model_corpus OUT_DIR\n");
    return 2;
  }
  const std::filesystem::path out = argv[1];
  std::filesystem::create_directories(out);
  const tr::FeatureLayout layout = tr::feature_layout_from_names({"q0", "q1", "v0"}, {"u0"}, {"q"});
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  tr::LogSequence seq;
  seq.file = "seed.csv";
  seq.state = "a";
  seq.y = Eigen::MatrixXd::NullaryExpr(3, 12, [&] { return normal(rng); });
  seq.u = Eigen::MatrixXd::NullaryExpr(1, 12, [&] { return normal(rng); });
  const tr::Normalization norm = tr::fit_normalization({seq}, layout);

  tr::HadynetModel bare = tr::new_model(layout, norm, {{"a", "ball"}, {"b", ""}}, 2, 3, 4, 11);
  tr::save_model((out / "bare.safetensors").string(), bare);

  tr::HadynetModel full = bare;
  tr::DetectionCalibration c;
  c.steps = 2;
  c.pb = Eigen::VectorXd::Constant(2, 0.25);
  c.mean = Eigen::VectorXd::Constant(3, 0.1);
  c.covariance = Eigen::MatrixXd::Identity(3, 3) * 2.0;
  c.inverse = Eigen::MatrixXd::Identity(3, 3) * 0.5;
  c.threshold = 3.5;
  c.samples = 40;
  c.source = "seed.csv";
  full.detection = c;
  tr::ValueRanges r;
  double v = 0.5;
  for (const tr::ValueRangeField& f : tr::kValueRangeFields) r.*f.member = (v *= 1.3);
  r.windows = 9;
  r.source = "seed.csv";
  full.ranges = r;
  full.sensor.delays.push_back({"v0", 2});
  full.sensor.crosstalk.push_back({"q1", "q0", 0.25});
  full.sensor.drifts.push_back({"q0", true, 0.01});
  full.sensor.curves.push_back({"q0", {0.0, 1.0, 4.0}, {0.0, 1.5, 3.5}});  // format_version 2
  full.sensor.clips.push_back({"q1", 1, 3.0});
  full.sensor.period_s = 0.2;
  full.held_out_logs = {{"seed.csv rows 8..11", "# format: hadynet-log\n# format_version: 1\n# dt_s: 0.2\nt,q0,q1,v0,u0\n"
                                                "0,1,2,3,0\n0.2,1,2,3,1\n"},
                        {"seed2.csv rows 5..6", "# format: hadynet-log\n"}};
  tr::save_model((out / "full.safetensors").string(), full);
  std::printf("make_model_corpus: wrote bare.safetensors and full.safetensors to %s\n", out.c_str());
  return 0;
}
