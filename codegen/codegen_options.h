// What a user chooses when generating a model header (hadynet codegen's
// options; docs/codegen.md). Choices left open (std::nullopt) are taken
// from the model's robot profile (datalog/robot_profile.h).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "firmware/core/model_contract.h"
#include "trainer/control/loss_weights.h"

namespace hadynet::codegen {

using Numeric = hadynet::firmware::Numeric;

// Grasp stabiliser constants written into the header (docs/method.md,
// "Grasp stabiliser"; seed paper III-F).
struct ControlOptions {
  int horizon = 8;                                       // N_control, 1 .. N_train
  int epochs = 3;                                        // N_epoch >= 1
  std::vector<double> alphas = {1.0, 0.5, 0.25, 0.125};  // step sizes (standardised units), > 0
  std::optional<int> truncation;                         // K >= 1; none: = horizon (full BPTT)
  // The loss weights' rule (beta, w2, w3, physical or standardised units;
  // trainer/control/loss_weights.h). In standardised units each weight must
  // fit Q(kFracLossW): <= 7.99.
  trainer::control::LossRule loss;
  // u channels the stabiliser may change (names); the others stay at "no
  // change". Empty: all. None: the model's robot profile (its
  // control_commands; all when it names none).
  std::optional<std::vector<std::string>> commands;
  // The groups of each loss class (trainer::channel_group: "fc3" -> "fc");
  // each must name at least one y channel, and a group in two classes is an
  // error. None: the model's robot profile (the hand's logs say f, fc / th /
  // l); a model without a profile has no loss classes unless they are given.
  std::optional<std::vector<std::string>> force_groups;
  std::optional<std::vector<std::string>> angle_groups;
  std::optional<std::vector<std::string>> length_groups;
};

struct CodegenOptions {
  Numeric numeric = Numeric::kQ15;
  std::string ns;         // C++ namespace; empty: "hadynet::model_q15" / "hadynet::model_f32"
  double headroom = 1.5;  // measured activation ranges are multiplied by it (>= 1)
  // The control period (s) for a model file that does not record it
  // (HadynetModel::period_s 0: trained before the format stored it). A model
  // that records one must not be given another.
  std::optional<double> period_s;
  ControlOptions control;
  // q15: the formats of an existing firmware, frac bits in the contract's
  // order (kFracIn, H, C, Y, Gate, EncW, LstmW, LstmAcc, DecW, Whiten, Z,
  // LossW). Set, the header takes them instead of choosing its own, so its
  // data can run in that firmware (a model image, docs/model-update.md); a
  // model that needs more range than one of them gives (fewer frac bits) is
  // refused, naming the format.
  std::optional<std::array<int, 12>> target_formats;
};

}  // namespace hadynet::codegen
