// A small synthetic model for codegen's tests: 6 observed channels in the
// hand's kinds of group (l, f, fc, th), 2 commands; x = (l, dl, f, fc, th,
// dth); hidden 5, PB 2, 3 states, N_train 10, period 0.2 s, generic weights
// and BN statistics, ranges consistent with the weights, and optionally
// detection statistics. Deterministic (fixed seeds), and built from portable
// code only (hadynet_model_file, hadynet_deploy_math), like codegen.
#pragma once

#include "trainer/hadynet_model.h"

namespace hadynet::codegen::test {

trainer::HadynetModel synthetic_model(bool with_detection);

}  // namespace hadynet::codegen::test
