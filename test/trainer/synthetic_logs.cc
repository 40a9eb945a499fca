#include "synthetic_logs.h"

#include <stdlib.h>

#include <array>
#include <random>
#include <stdexcept>
#include <system_error>

#include "datalog/log_writer.h"
#include "test_batches.h"
#include "trainer/training.h"
#include "trainer/window_dataset.h"

namespace hadynet::trainer::testing {

namespace {

constexpr double kDt_s = 0.2;
constexpr double kDamping_per_s = 0.6;

}  // namespace

datalog::LogTable spring_log(double stiffness, int steps, std::uint64_t seed,
                             const std::string& state, const std::string& object) {
  std::mt19937_64 rng(seed);
  datalog::LogTable table;
  table.metadata.set("format", "hadynet-log");
  table.metadata.set("format_version", "1");
  table.metadata.set("dt_s", "0.2");
  table.metadata.set("state", state);
  if (!object.empty()) table.metadata.set("object", object);
  table.columns = {"t", "q0", "q1", "v0", "v1", "u0", "u1", "aux_energy"};
  std::array<double, 2> q{uniform(rng, -0.5, 0.5), uniform(rng, -0.5, 0.5)};
  std::array<double, 2> v{uniform(rng, -0.5, 0.5), uniform(rng, -0.5, 0.5)};
  for (int t = 0; t < steps; ++t) {
    const std::array<double, 2> u{uniform(rng, -1.0, 1.0), uniform(rng, -1.0, 1.0)};
    double energy = 0.0;
    for (int i = 0; i < 2; ++i) energy += 0.5 * (v[i] * v[i] + stiffness * (1.0 + 0.5 * i) * q[i] * q[i]);
    table.append_row({t * kDt_s, q[0], q[1], v[0], v[1], u[0], u[1], energy});
    for (int i = 0; i < 2; ++i) {
      const double k = stiffness * (1.0 + 0.5 * i);
      v[i] += kDt_s * (-k * q[i] - kDamping_per_s * v[i] + u[i]);
      q[i] += kDt_s * v[i];
    }
  }
  return table;
}

FeatureLayout spring_layout() {
  return feature_layout(spring_log(1.0, 2, 0, "layout"), "spring.csv", kSpringDeltaGroups);
}

LogSequence spring_sequence(double stiffness, int steps, std::uint64_t seed,
                            const std::string& state) {
  return log_sequence(spring_log(stiffness, steps, seed, state), state + ".csv", spring_layout());
}

TempDir::TempDir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "hadynet_trainer_XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string TempDir::write_log(const std::string& relative, const datalog::LogTable& table) const {
  const std::filesystem::path p = path_ / relative;
  std::filesystem::create_directories(p.parent_path());
  datalog::write_log(p, table);
  return p.string();
}

SpringModel trained_spring_model(int epochs) {
  SpringModel s;
  s.layout = spring_layout();
  s.train = {spring_sequence(kSoftStiffness, 80, 101, "soft"),
             spring_sequence(kStiffStiffness, 80, 102, "stiff")};
  s.norm = fit_normalization(s.train, s.layout);
  s.model = new_model(s.layout, s.norm, {{"soft", "none"}, {"stiff", "none"}}, /*pb_dim=*/2,
                      /*hidden=*/12, kSpringTrainSteps, /*seed=*/11);
  const WindowDataset data(s.train, {0, 1}, s.layout, s.norm, kSpringTrainSteps);
  std::vector<int> ids(static_cast<std::size_t>(data.size()));
  for (int i = 0; i < data.size(); ++i) ids[static_cast<std::size_t>(i)] = i;
  TrainOptions options;
  options.epochs = epochs;
  options.batch = 25;
  options.lr = 1e-2;
  options.seed = 11;
  TrainingState state;
  train(s.model, state, data, ids, {}, options, [](const EpochStats&) {});
  return s;
}

}  // namespace hadynet::trainer::testing
