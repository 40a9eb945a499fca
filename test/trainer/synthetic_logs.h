// Tiny synthetic HADYNET logs for the trainer pipeline tests (log_dataset ..
// recognition): two independent damped mass-springs, one dynamics state per
// stiffness k.
//   v' = v + dt (-k_i q - c v + u_i),  q' = q + dt v',   k_i = k (1 + 0.5 i)
// dt = 0.2 s, damping c = 0.6 1/s, commands u_i uniform in [-1, 1] (force per
// mass); row t holds y_t and the command u_t that acts on y_{t+1}.
// Columns: t, q0, q1, v0, v1, u0, u1, aux_energy. The positions "q" are the
// delta group (kSpringDeltaGroups), so x = (q0, q1, dq0, dq1, v0, v1).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "datalog/log_table.h"
#include "trainer/hadynet_model.h"
#include "trainer/log_dataset.h"
#include "trainer/normalization.h"

namespace hadynet::trainer::testing {

inline const std::vector<std::string> kSpringDeltaGroups = {"q"};
inline constexpr double kSoftStiffness = 1.0;   // state "soft"  (1/s^2)
inline constexpr double kStiffStiffness = 6.0;  // state "stiff" (1/s^2)

// A valid log table (format, format_version, dt_s, state, object metadata)
// of `steps` rows from a random start drawn from `seed`.
datalog::LogTable spring_log(double stiffness, int steps, std::uint64_t seed,
                             const std::string& state, const std::string& object = "");

// The layout of spring_log's header with kSpringDeltaGroups.
FeatureLayout spring_layout();

// spring_log extracted with spring_layout() (file name "<state>.csv").
LogSequence spring_sequence(double stiffness, int steps, std::uint64_t seed,
                            const std::string& state);

// A fresh folder under the system temp folder, removed with its content.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // Writes `table` to path()/relative (creating folders); returns the path.
  std::string write_log(const std::string& relative, const datalog::LogTable& table) const;

 private:
  std::filesystem::path path_;
};

// A small trained HADYNET on two states, "soft" (k = 1) and "stiff" (k = 6):
// one 80-step log each, hidden 12, PB 2, N_train 5, Adam lr 1e-2, batch 25,
// `epochs` epochs, seed 11. Deterministic (same bits on every call).
struct SpringModel {
  FeatureLayout layout;
  std::vector<LogSequence> train;  // train[k] belongs to PB row k
  Normalization norm;
  HadynetModel model;
};
inline constexpr int kSpringTrainSteps = 5;
SpringModel trained_spring_model(int epochs = 40);

// Error-message helper: true if `text` contains `part`.
inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace hadynet::trainer::testing
