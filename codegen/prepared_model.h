// The first step of codegen (codegen.h: prepare -> quantise -> emit): the
// model checked, the options completed from its robot profile, and every
// derived quantity the header needs computed once, in double: the encoder
// with its batch norm folded in, the detection whitening, the loss classes
// and weights, the commands the stabiliser may change, the control period.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "codegen/codegen_options.h"
#include "trainer/control/loss_weights.h"
#include "trainer/deploy_prep.h"
#include "trainer/hadynet_model.h"

namespace hadynet::codegen {

struct PreparedModel {
  const trainer::HadynetModel& model;
  CodegenOptions options;               // every choice made (the profile's where the caller left it open)
  trainer::FoldedEncoder encoder;       // batch norm folded (trainer/deploy_prep.h)
  std::optional<Eigen::MatrixXd> whitening;  // W, W^T W = Sigma_e^-1 (trainer::whitening_matrix); when calibrated
  std::vector<firmware::LossClass> loss_classes;  // per y channel
  trainer::control::LossWeights loss_weights;     // per y channel
  std::vector<bool> active_commands;              // per u channel: the stabiliser may change it
  double period_s = 0;                            // the control period, s
  std::uint32_t period_us = 0;                    // the same, rounded to whole microseconds (kPeriodUs)
};

// Checks the model and the options and prepares them; throws UnsupportedModel
// naming the first problem. `model` must outlive the result.
PreparedModel prepare(const trainer::HadynetModel& model, const CodegenOptions& options);

}  // namespace hadynet::codegen
