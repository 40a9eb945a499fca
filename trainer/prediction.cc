#include "trainer/prediction.h"

#include <numeric>
#include <stdexcept>

#include "trainer/output_clip.h"
#include "trainer/window_dataset.h"

namespace hadynet::trainer {

Eigen::MatrixXd simulate(const HadynetModel& model, const Eigen::VectorXd& x0,
                         const Eigen::MatrixXd& u, const Eigen::VectorXf& pb) {
  const HadynetDims& d = model.params.dims;
  if (x0.size() != d.x || u.rows() != d.u || u.cols() < 1 || pb.size() != d.pb) {
    throw std::invalid_argument("simulate: x0, u or PB size does not match the model");
  }
  WindowBatch<float> batch;
  batch.x0 = model.norm.x.standardize(x0).cast<float>();
  batch.u = ((u.colwise() - model.norm.u.mean).array().colwise() / model.norm.u.std.array())
                .matrix()
                .cast<float>();
  batch.pb = pb;
  HadynetNetwork<float> net;
  const Matrix<float>& y_hat = net.forward(model.params, batch, BnMode::kEval);
  Eigen::MatrixXd y = y_hat.cast<double>();
  for (Eigen::Index k = 0; k < y.cols(); ++k) y.col(k) = model.norm.y.physical(y.col(k));
  apply_output_clips(model, y);
  return y;
}

Eigen::MatrixXd prediction_errors(const HadynetModel& model, const LogSequence& seq,
                                  const Eigen::VectorXf& pb, int steps) {
  if (steps < 1) throw std::invalid_argument("prediction steps must be >= 1");
  const WindowDataset data({seq}, {0}, model.layout, model.norm, steps);
  Eigen::MatrixXd errors(data.y_dim(), data.size());
  if (data.size() == 0) return errors;
  std::vector<int> ids(static_cast<std::size_t>(data.size()));
  std::iota(ids.begin(), ids.end(), 0);
  WindowBatch<float> batch;
  Matrix<float> y;
  data.gather(ids, batch, y);
  batch.pb = pb.replicate(1, data.size());
  HadynetNetwork<float> net;
  Matrix<float> y_hat = net.forward(model.params, batch, BnMode::kEval);
  clip_standardised(model, y_hat);
  const Eigen::Index B = data.size();
  errors = (y_hat.rightCols(B) - y.rightCols(B)).cast<double>();  // last step of each window
  return errors;
}

}  // namespace hadynet::trainer
