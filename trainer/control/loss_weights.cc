#include "trainer/control/loss_weights.h"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "trainer/log_dataset.h"

namespace hadynet::trainer::control {

std::vector<LossClass> loss_classes(const std::vector<std::string>& y_names, const LossGroups& groups) {
  std::vector<LossClass> classes(y_names.size(), LossClass::kNone);
  std::map<std::string, std::string> class_of_group;
  const auto assign = [&](const std::vector<std::string>& class_groups, LossClass cls, const char* name) {
    for (const std::string& g : class_groups) {
      const auto [it, inserted] = class_of_group.emplace(g, name);
      if (!inserted) {
        throw std::invalid_argument("loss group '" + g + "' is in both the " + it->second + " and the " + name +
                                    " class");
      }
      bool any = false;
      for (std::size_t i = 0; i < y_names.size(); ++i) {
        if (channel_group(y_names[i]) == g) {
          classes[i] = cls;
          any = true;
        }
      }
      if (!any) throw std::invalid_argument(std::string(name) + " loss group '" + g + "' names no y channel of the model");
    }
  };
  assign(groups.force, LossClass::kForce, "force");
  assign(groups.angle, LossClass::kAngle, "angle");
  assign(groups.length, LossClass::kLength, "length");
  return classes;
}

LossWeights loss_weights(const std::vector<LossClass>& classes, const Eigen::VectorXd& y_std, const LossRule& rule) {
  const Eigen::Index n = static_cast<Eigen::Index>(classes.size());
  if (y_std.size() != n) throw std::invalid_argument("loss weights: one std per loss class needed");
  const auto class_weight = [&](LossClass c, bool up) {
    switch (c) {
      case LossClass::kForce: return up ? 1.0 : rule.beta;
      case LossClass::kAngle: return rule.w2;
      case LossClass::kLength: return rule.w3;
      case LossClass::kNone: break;
    }
    return 0.0;
  };
  LossWeights w{Eigen::VectorXd(n), Eigen::VectorXd(n)};
  for (Eigen::Index i = 0; i < n; ++i) {
    const double s2 = rule.physical_units ? y_std(i) * y_std(i) : 1.0;
    w.up(i) = class_weight(classes[static_cast<std::size_t>(i)], true) * s2;
    w.down(i) = class_weight(classes[static_cast<std::size_t>(i)], false) * s2;
  }
  if (rule.physical_units) {
    const double largest = n == 0 ? 0.0 : std::max(w.up.maxCoeff(), w.down.maxCoeff());
    if (!(largest > 0)) {
      throw std::invalid_argument("every loss weight is zero: the stabiliser would have nothing to minimise");
    }
    const double scale = 1.0 / largest;  // (a product, as the generated headers were always computed)
    w.up *= scale;
    w.down *= scale;
  }
  return w;
}

}  // namespace hadynet::trainer::control
