// Per-channel standardisation of x, u and y (docs/method.md, "Windows and standardisation"): the
// network sees (v - mean) / std. Fitted on the training logs and stored with
// the model so every later use (adapt, detect, codegen) scales identically.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "trainer/log_dataset.h"

namespace hadynet::trainer {

struct ChannelScaling {
  Eigen::VectorXd mean;  // physical units
  Eigen::VectorXd std;   // physical units, > 0

  Eigen::VectorXd standardize(const Eigen::VectorXd& v) const {
    return (v - mean).cwiseQuotient(std);
  }
  Eigen::VectorXd physical(const Eigen::VectorXd& s) const {
    return s.cwiseProduct(std) + mean;
  }
};

struct Normalization {
  ChannelScaling x, u, y;
};

// Relative floor of a channel's std: at least this fraction of the median std
// of the channels of its group (same name prefix). A nearly constant channel
// (the thumb-tip loadcell touches almost nothing) would otherwise turn its
// quantisation noise into unit-variance targets and dominate the loss.
inline constexpr double kStdFloorOfGroupMedian = 0.1;

// Mean and (population) std per channel over every step of every sequence
// (x over steps t >= 1). A channel whose std is still 0 after the floor (the
// whole group constant) gets std 1. Throws std::invalid_argument if there is
// no data.
Normalization fit_normalization(const std::vector<LogSequence>& sequences,
                                const FeatureLayout& layout);

}  // namespace hadynet::trainer
