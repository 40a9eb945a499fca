// A trained HADYNET model: weights, the channels and standardisation they
// expect, the PB table with its states, optional detection calibration,
// hyper-parameters and provenance. Stored as one safetensors file (see
// model_file.h and docs/model-file.md).
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "trainer/hadynet_params.h"
#include "trainer/log_dataset.h"
#include "trainer/normalization.h"

namespace hadynet::trainer {

// One row of the PB table.
struct PbState {
  std::string name;    // dynamics-state id, e.g. "Cylinder/i2/w0"
  std::string object;  // grasped object label, e.g. "Cylinder" ("" if unknown)
};

// Contact detection statistics (DESIGN.md section 4), in standardised y units.
struct DetectionCalibration {
  int steps = 0;              // N_detect: y_t is predicted from x_{t-N} and u_[t-N, t)
  Eigen::VectorXd pb;         // the PB detection runs with (fitted on contact-free data)
  Eigen::VectorXd mean;       // mu_e of e = y_est - y
  Eigen::MatrixXd covariance; // Sigma_e
  Eigen::MatrixXd inverse;    // regularised Sigma_e^-1 (see detection.h)
  double threshold = 0.0;     // C_detect on d
  long samples = 0;           // errors the statistics were computed from
  std::string source;         // logs the calibration used
};

struct HadynetModel {
  FeatureLayout layout;
  Normalization norm;
  HadynetParams<float> params;
  std::vector<PbState> states;  // params.pb row k belongs to states[k]
  int train_steps = 10;         // N_train of the windows it was trained on
  long bn_batches_tracked = 0;  // enc_bn.num_batches_tracked (PyTorch buffer)
  std::optional<DetectionCalibration> detection;
  std::map<std::string, std::string> hyper_parameters;  // e.g. "lr" -> "0.001"
  std::map<std::string, std::string> provenance;        // data_hash, git_commit, logs, ...

  // Row of the PB table for a state name; -1 if absent.
  int state_index(const std::string& name) const;
  // Throws std::invalid_argument if the parts disagree (dims vs channels vs
  // normalisation vs PB table vs detection sizes).
  void check_consistent() const;
};

}  // namespace hadynet::trainer
