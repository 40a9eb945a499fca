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

#include "datalog/robot_profile.h"
#include "trainer/hadynet_params.h"
#include "trainer/log_dataset.h"
#include "trainer/normalization.h"
#include "trainer/sensor_model.h"

namespace hadynet::trainer {

// One row of the PB table.
struct PbState {
  std::string name;    // dynamics-state id, e.g. "Cylinder/i2/w0"
  std::string object;  // grasped object label, e.g. "Cylinder" ("" if unknown)
};

// Contact detection statistics (docs/method.md, "Detection"), in standardised y units.
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

// Largest absolute value of each quantity the firmware's forward computes, in
// standardised units (measure_ranges in trainer/deploy_prep.h). Codegen picks
// the fixed-point formats from them (docs/codegen.md).
struct ValueRanges {
  double x = 0, u = 0, pb = 0;          // inputs
  double enc_pre = 0;                   // folded encoder pre-activation (before ReLU)
  double h = 0;                         // h_0 .. h_N
  double gate_pre = 0;                  // LSTM gate pre-activations (all four gates)
  double c = 0;                         // cell states
  double y = 0;                         // decoder outputs
  double enc_weight = 0, lstm_weight = 0, dec_weight = 0;  // folded / raw weights
  double enc_bias = 0, lstm_bias = 0, dec_bias = 0;
  long windows = 0;    // windows the activations were measured on
  std::string source;  // what they came from, e.g. "36 logs (data_hash ...), all windows"

  bool operator==(const ValueRanges&) const = default;
};

// The numeric fields of ValueRanges by their model-file key (docs/model-file.md).
struct ValueRangeField {
  const char* name;
  double ValueRanges::*member;
};
inline constexpr ValueRangeField kValueRangeFields[] = {
    {"x", &ValueRanges::x},
    {"u", &ValueRanges::u},
    {"pb", &ValueRanges::pb},
    {"enc_pre", &ValueRanges::enc_pre},
    {"h", &ValueRanges::h},
    {"gate_pre", &ValueRanges::gate_pre},
    {"c", &ValueRanges::c},
    {"y", &ValueRanges::y},
    {"enc_weight", &ValueRanges::enc_weight},
    {"lstm_weight", &ValueRanges::lstm_weight},
    {"dec_weight", &ValueRanges::dec_weight},
    {"enc_bias", &ValueRanges::enc_bias},
    {"lstm_bias", &ValueRanges::lstm_bias},
    {"dec_bias", &ValueRanges::dec_bias},
};

// One log kept inside the model file, as the text of a HADYNET log
// (docs/log-format.md).
struct StoredLog {
  std::string name;  // where its rows came from, e.g. "train/a.csv rows 441..499"
  std::string text;  // datalog::format_log() text; parse_log() reads it back bit for bit

  bool operator==(const StoredLog&) const = default;
};

struct HadynetModel {
  FeatureLayout layout;
  Normalization norm;
  HadynetParams<float> params;
  std::vector<PbState> states;  // params.pb row k belongs to states[k]
  int train_steps = 10;         // N_train of the windows it was trained on
  // The control period of the logs it was trained on (their dt_s), s: one
  // step of the network. 0: not recorded (a model file written before the
  // format stored it); codegen then needs the period as an option.
  double period_s = 0;
  long bn_batches_tracked = 0;  // enc_bn.num_batches_tracked (PyTorch buffer)
  std::optional<DetectionCalibration> detection;
  std::optional<ValueRanges> ranges;  // measured value ranges (needed by codegen)
  // The robot profile of the logs it was trained on (datalog/robot_profile.h):
  // loss classes, stabiliser commands, board channels, contact sums. Its
  // delta_groups are always layout.delta_groups (the model file stores them
  // once, with the channels). Empty: a robot whose logs carry no profile.
  datalog::RobotProfile profile;
  SensorModel sensor;  // measured channels from the network's (sensor_model.h); empty: the same
  // The rows of each training log that no training window touched (the tail
  // `train --held-out` kept out, held_out_logs.h), as logs: clean data that
  // is neither training data nor, as a rule, a log under test. The residual
  // loop calibrates its null on them by default (docs/residual.md). Empty:
  // none stored (--held-out 0, or a model written before the format had them).
  std::vector<StoredLog> held_out_logs;
  std::map<std::string, std::string> hyper_parameters;  // e.g. "lr" -> "0.001"
  std::map<std::string, std::string> provenance;        // data_hash, git_commit, logs, ...

  // Row of the PB table for a state name; -1 if absent.
  int state_index(const std::string& name) const;
  // Throws std::invalid_argument if the parts disagree (dims vs channels vs
  // normalisation vs PB table vs detection sizes; ranges negative or not finite).
  void check_consistent() const;
};

}  // namespace hadynet::trainer
