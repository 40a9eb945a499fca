#include "codegen/prepared_model.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "codegen/checks.h"
#include "codegen/header_text.h"
#include "codegen/unsupported_model.h"
#include "trainer/detection.h"

namespace hadynet::codegen {

using trainer::HadynetModel;

namespace {

// The options with every choice the caller left open taken from the model's
// robot profile (the stabiliser's commands and loss classes).
CodegenOptions with_profile(CodegenOptions o, const HadynetModel& model) {
  ControlOptions& c = o.control;
  const datalog::RobotProfile& p = model.profile;
  if (!c.commands) c.commands = p.control_commands;
  if (!c.force_groups) c.force_groups = p.force_groups;
  if (!c.angle_groups) c.angle_groups = p.angle_groups;
  if (!c.length_groups) c.length_groups = p.length_groups;
  return o;
}

// The model's period, or the option's for a model that does not record one.
double control_period_s(const HadynetModel& model, const CodegenOptions& o) {
  if (o.period_s) {
    if (!(std::isfinite(*o.period_s) && *o.period_s > 0)) {
      reject("period " + num(*o.period_s) + " s must be a positive number of seconds");
    }
    if (model.period_s > 0 && *o.period_s != model.period_s) {
      reject("the model was trained on logs of period " + exact_num(model.period_s) + " s; the period option (" +
             exact_num(*o.period_s) + " s) is only for model files that do not record theirs");
    }
    return *o.period_s;
  }
  if (!(model.period_s > 0)) {
    reject("the model file does not record its control period (trained before model files stored it): "
           "give --period-s S, the training logs' dt_s");
  }
  return model.period_s;
}

}  // namespace

PreparedModel prepare(const HadynetModel& model, const CodegenOptions& given) {
  check_model(model);
  PreparedModel p{model, with_profile(given, model), trainer::fold_batch_norm(model.params), {}, {}, {}, {}, 0, 0};
  check_stored_ranges(model, p.encoder);
  check_options(model, p.options);
  const ControlOptions& c = p.options.control;
  try {
    if (model.detection) p.whitening = trainer::whitening_matrix(model.detection->inverse);
    p.loss_classes = trainer::control::loss_classes(model.layout.y_names,
                                                    {c.force_groups.value(), c.angle_groups.value(), c.length_groups.value()});
    p.loss_weights = trainer::control::loss_weights(p.loss_classes, model.norm.y.std, c.loss);
  } catch (const std::invalid_argument& e) {
    reject(e.what());
  }
  p.active_commands = active_commands(model, c);
  p.period_s = control_period_s(model, p.options);
  const double us = std::round(p.period_s * 1e6);
  if (!(us >= 1 && us <= std::numeric_limits<std::uint32_t>::max())) {
    reject("control period " + num(p.period_s) + " s is not between 1 us and 4294 s");
  }
  p.period_us = static_cast<std::uint32_t>(us);
  return p;
}

}  // namespace hadynet::codegen
