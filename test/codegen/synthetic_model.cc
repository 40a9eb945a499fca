#include "test/codegen/synthetic_model.h"

#include <algorithm>
#include <random>

#include <Eigen/Cholesky>

#include "trainer/batch_norm_fold.h"
#include "trainer/log_dataset.h"

namespace hadynet::codegen::test {

using trainer::HadynetModel;

HadynetModel synthetic_model(bool with_detection) {
  HadynetModel m;
  m.layout = trainer::feature_layout_from_names({"l0", "l1", "f0", "fc0", "fc1", "th0"},
                                                {"u0", "u1"}, {"l", "th"});
  // The hand's kinds of channel, as its logs' robot profile names them: the
  // stabiliser's loss classes come from here.
  m.profile.delta_groups = m.layout.delta_groups;
  m.profile.force_groups = {"f", "fc"};
  m.profile.angle_groups = {"th"};
  m.profile.length_groups = {"l"};
  trainer::HadynetDims d;
  d.x = static_cast<int>(m.layout.x_names.size());
  d.u = 2;
  d.y = 6;
  d.pb = 2;
  d.hidden = 5;
  d.states = 3;
  m.params = trainer::HadynetParams<float>::initialized(d, 7);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  for (Eigen::Index i = 0; i < d.hidden; ++i) {
    m.params.enc_bn_weight(i) = 1.0f + 0.3f * uni(rng);
    m.params.enc_bn_bias(i) = 0.2f * uni(rng);
    m.params.enc_bn_running_mean(i) = 0.1f * uni(rng);
    m.params.enc_bn_running_var(i) = 1.5f + uni(rng);
  }
  for (Eigen::Index i = 0; i < m.params.pb.size(); ++i) m.params.pb.data()[i] = 0.8f * uni(rng);
  m.states = {{"soft/i0", "Ball"}, {"stiff/i0", "Hammer \"big\""}, {"none", ""}};
  m.train_steps = 10;
  m.period_s = 0.2;  // the hand's logs' dt_s
  const auto scaling = [&](int n, double mean0) {
    trainer::ChannelScaling s;
    s.mean = Eigen::VectorXd::LinSpaced(n, mean0, mean0 + 3.0);
    s.std = Eigen::VectorXd::LinSpaced(n, 0.5, 2.0);
    return s;
  };
  m.norm.x = scaling(d.x, 1.0);
  m.norm.u = scaling(d.u, 0.0);
  m.norm.y = scaling(d.y, -2.0);
  trainer::ValueRanges r;
  r.x = 2.5;
  r.u = 1.2;
  r.pb = m.params.pb.cwiseAbs().maxCoeff();
  r.enc_pre = 3.0;
  r.h = 0.9;
  r.gate_pre = 4.0;
  r.c = 1.7;
  r.y = 3.1;
  const trainer::FoldedEncoder enc = trainer::fold_batch_norm(m.params);
  r.enc_weight = enc.weight.cwiseAbs().maxCoeff();
  r.lstm_weight = std::max(m.params.lstm_weight_ih.cwiseAbs().maxCoeff(),
                           m.params.lstm_weight_hh.cwiseAbs().maxCoeff());
  r.dec_weight = m.params.dec_weight.cwiseAbs().maxCoeff();
  r.windows = 100;
  r.source = "synthetic";
  m.ranges = r;
  if (with_detection) {
    trainer::DetectionCalibration c;
    c.steps = 3;
    c.pb = Eigen::VectorXd::Constant(d.pb, 0.3);
    c.mean = Eigen::VectorXd::LinSpaced(d.y, -0.2, 0.2);
    Eigen::MatrixXd a(d.y, d.y);
    std::normal_distribution<double> normal;
    for (Eigen::Index i = 0; i < a.size(); ++i) a.data()[i] = normal(rng);
    c.covariance = a * a.transpose() + 0.1 * Eigen::MatrixXd::Identity(d.y, d.y);
    // (Well conditioned: + 0.1 I.) Portable code only, like codegen: the
    // golden headers (golden_header_test.cc) must be the same on every machine.
    c.inverse = c.covariance.ldlt().solve(Eigen::MatrixXd::Identity(d.y, d.y));
    c.threshold = 5.0;
    c.samples = 200;
    c.source = "synthetic";
    m.detection = c;
  }
  return m;
}

}  // namespace hadynet::codegen::test
