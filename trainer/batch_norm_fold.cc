#include "trainer/batch_norm_fold.h"

#include <Eigen/Core>

namespace hadynet::trainer {

FoldedEncoder fold_batch_norm(const HadynetParams<float>& params) {
  params.check_shapes();
  const Eigen::ArrayXd scale =
      params.enc_bn_weight.cast<double>().array() /
      (params.enc_bn_running_var.cast<double>().array() + kBnEps).sqrt();
  FoldedEncoder folded;
  folded.weight = (scale.matrix().asDiagonal() * params.enc_weight.cast<double>()).cast<float>();
  folded.bias = (scale * (params.enc_bias.cast<double>() - params.enc_bn_running_mean.cast<double>())
                              .array() +
                 params.enc_bn_bias.cast<double>().array())
                    .matrix()
                    .cast<float>();
  return folded;
}

}  // namespace hadynet::trainer
