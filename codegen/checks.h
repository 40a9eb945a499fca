// The checks of codegen's first step (prepared_model.h): a model it can
// generate and options that make sense for it. Each throws UnsupportedModel
// naming the first problem.
#pragma once

#include <string>
#include <vector>

#include "codegen/codegen_options.h"
#include "trainer/deploy_prep.h"
#include "trainer/hadynet_model.h"

namespace hadynet::codegen {

// The largest loss weight in standardised units: Q(kFracLossW) = Q12 of an int16.
inline constexpr int kFracLossW = 12;
inline constexpr double kMaxLossWeight = 32767.0 / 4096.0;

// Identifiers joined by "::", none a keyword or reserved.
void check_namespace(const std::string& ns);

// A consistent model (HadynetModel::check_consistent), every dimension >= 1,
// finite tensors and standardisation, measured value ranges present, and
// detection statistics usable.
void check_model(const trainer::HadynetModel& model);

// The stored value ranges were measured with these weights (the folded
// encoder's, the LSTM's, the decoder's largest magnitudes).
void check_stored_ranges(const trainer::HadynetModel& model, const trainer::FoldedEncoder& encoder);

// Options (with every choice made: codegen_options.h) that fit the model:
// namespace, headroom, horizon <= N_train, epochs, truncation, alphas, loss
// weights.
void check_options(const trainer::HadynetModel& model, const CodegenOptions& options);

// kControlActive: which u channels the stabiliser may change (options with
// the commands chosen). A derived input (sign_u0, hyst_u0:
// trainer/derived_inputs.h) is computed from a command, never one the
// stabiliser sets.
std::vector<bool> active_commands(const trainer::HadynetModel& model, const ControlOptions& control);

}  // namespace hadynet::codegen
