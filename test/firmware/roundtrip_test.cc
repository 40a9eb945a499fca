// Round trip trainer (double) -> generated f32 -> generated q15 on held-out
// plant logs: forward errors per channel, the stabiliser's gradient
// direction and chosen command, and detection decisions. Every bound is a
// row of docs/tolerances.md (tolerances.h); the measured values are printed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "firmware/core/boundary.h"
#include "firmware/core/grasp_stabilizer.h"
#include "firmware/core/hadynet_net.h"
#include "firmware/core/hadynet_runtime.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "test/firmware/held_out_logs.h"
#include "test/firmware/tolerances.h"
#include "trainer/control/reference_stabiliser.h"
#include "trainer/detection.h"
#include "trainer/hadynet_network.h"

namespace hadynet {
namespace {

using Q = model_q15::Model;
using F = model_f32::Model;
using trainer::HadynetModel;
using trainer::LogSequence;

template <class M>
void frame(const LogSequence& s, int t, float (&y)[M::kY]) {
  for (int i = 0; i < M::kY; ++i) y[i] = static_cast<float>(s.y(i, t));
}

// The firmware's rollout of `steps` log commands from x_t: standardised y.
template <class M>
Eigen::MatrixXd firmware_rollout(const LogSequence& s, int t, int steps, const Eigen::VectorXd& pb) {
  using B = firmware::Boundary<M>;
  using Value = typename M::Value;
  firmware::HadynetNet<M> net;
  float yt[M::kY], yp[M::kY], pbf[M::kPb];
  frame<M>(s, t, yt);
  frame<M>(s, t - 1, yp);
  for (int i = 0; i < M::kPb; ++i) pbf[i] = static_cast<float>(pb(i));
  Value x[M::kX], pbv[M::kPb], u[M::kU], y[M::kY];
  B{}.x_from_frames(yt, yp, x);
  B::real_to_in(pbf, pbv);
  net.encode(x, pbv);
  Eigen::MatrixXd out(M::kY, steps);
  for (int k = 0; k < steps; ++k) {
    float uf[M::kU];
    for (int i = 0; i < M::kU; ++i) uf[i] = static_cast<float>(s.u(i, t + k));
    B{}.u_to_model(uf, u);
    net.step(u, y);
    for (int i = 0; i < M::kY; ++i) out(i, k) = firmware::Numerics<M>::template to_real<M::kFracY>(y[i]);
  }
  return out;
}

// The trainer's double forward of the same window (BN eval, explicit PB).
Eigen::MatrixXd trainer_rollout(const LogSequence& s, int t, const Eigen::MatrixXd& u_std,
                                const Eigen::VectorXd& pb) {
  const HadynetModel& m = test::build_model();
  static const trainer::HadynetParams<double> params = m.params.cast<double>();
  trainer::WindowBatch<double> batch;
  batch.x0 = m.norm.x.standardize(trainer::initial_state(m.layout, s, t));
  batch.u = u_std;
  batch.pb = pb;
  trainer::HadynetNetwork<double> net;
  return net.forward(params, batch, trainer::BnMode::kEval);
}

Eigen::MatrixXd standardised_commands(const LogSequence& s, int t, int steps) {
  const HadynetModel& m = test::build_model();
  Eigen::MatrixXd u(s.u.rows(), steps);
  for (int k = 0; k < steps; ++k) u.col(k) = m.norm.u.standardize(s.u.col(t + k));
  return u;
}

struct ChannelErrors {
  Eigen::ArrayXd max_abs, sum_sq;
  long count = 0;
  explicit ChannelErrors(int n) : max_abs(Eigen::ArrayXd::Zero(n)), sum_sq(Eigen::ArrayXd::Zero(n)) {}
  void add(const Eigen::MatrixXd& diff) {
    max_abs = max_abs.max(diff.cwiseAbs().rowwise().maxCoeff().array());
    sum_sq += diff.array().square().rowwise().sum();
    count += diff.cols();
  }
  Eigen::ArrayXd rms() const { return (sum_sq / static_cast<double>(count)).sqrt(); }
};

const std::vector<LogSequence>& logs() {
  static const std::vector<LogSequence> l = {test::held_out_sequence("None", "random2"),
                                             test::held_out_sequence("Cylinder", "random2"),
                                             test::held_out_sequence("Ball", "random1")};
  return l;
}

Eigen::VectorXd detection_pb() { return test::build_model().detection->pb; }

TEST(FirmwareRoundTrip, ForwardMatchesTrainerPerChannel) {
  const HadynetModel& m = test::build_model();
  ASSERT_TRUE(m.detection.has_value());
  const int n = m.train_steps;
  ChannelErrors f32(Q::kY), q15(Q::kY), q_vs_f(Q::kY);
  for (const LogSequence& s : logs()) {
    for (int t = 1; t + n < s.steps(); t += 5) {
      const Eigen::MatrixXd ref = trainer_rollout(s, t, standardised_commands(s, t, n), detection_pb());
      const Eigen::MatrixXd yf = firmware_rollout<F>(s, t, n, detection_pb());
      const Eigen::MatrixXd yq = firmware_rollout<Q>(s, t, n, detection_pb());
      f32.add(yf - ref);
      q15.add(yq - ref);
      q_vs_f.add(yq - yf);
    }
  }
  std::printf("%-6s %12s %12s %12s %12s  (standardised units, %ld window steps)\n", "chan", "f32 max",
              "f32 rms", "q15 max", "q15 rms", f32.count);
  for (int i = 0; i < Q::kY; ++i)
    std::printf("%-6s %12.3g %12.3g %12.3g %12.3g\n", Q::kYNames[i], f32.max_abs(i), f32.rms()(i), q15.max_abs(i),
                q15.rms()(i));
  EXPECT_LE(f32.max_abs.maxCoeff(), test::tolerance("forward.f32.max"));
  EXPECT_LE(f32.rms().maxCoeff(), test::tolerance("forward.f32.rms"));
  EXPECT_LE(q15.max_abs.maxCoeff(), test::tolerance("forward.q15.max"));
  EXPECT_LE(q15.rms().maxCoeff(), test::tolerance("forward.q15.rms"));
}

// ---- the stabiliser: gradient direction and chosen command

using Plan = trainer::control::StabiliserPlan;

// Standardised command "no change" (u = 0 physical).
Eigen::VectorXd hold_command() {
  const HadynetModel& m = test::build_model();
  return m.norm.u.standardize(Eigen::VectorXd::Zero(m.layout.u_names.size()));
}

template <class M>
Plan firmware_plan(const LogSequence& s, int t, int t_ref, int epochs, int truncation) {
  using B = firmware::Boundary<M>;
  using N = firmware::Numerics<M>;
  using Value = typename M::Value;
  static firmware::GraspStabilizer<M> stab;  // large: traces
  static firmware::HadynetNet<M> net;
  Value hold[M::kU], y_ref[M::kY], y_now[M::kY], x[M::kX], pbv[M::kPb], cmd[M::kU];
  const Eigen::VectorXd h = hold_command();
  for (int i = 0; i < M::kU; ++i) hold[i] = N::template from_real<M::kFracIn>(static_cast<float>(h(i)));
  stab.reset(hold);
  float yr[M::kY], yt[M::kY], yp[M::kY], pbf[M::kPb];
  frame<M>(s, t_ref, yr);
  frame<M>(s, t, yt);
  frame<M>(s, t - 1, yp);
  B{}.y_to_model(yr, y_ref);
  stab.set_reference(y_ref);
  B{}.x_from_frames(yt, yp, x);
  B{}.y_to_model(yt, y_now);
  const Eigen::VectorXd pb = detection_pb();
  for (int i = 0; i < M::kPb; ++i) pbf[i] = static_cast<float>(pb(i));
  B::real_to_in(pbf, pbv);
  stab.settings().epochs = epochs;
  stab.settings().truncation = truncation;
  stab.plan(net, x, y_now, pbv, cmd);
  Plan p;
  p.direction.resize(M::kControlHorizon * M::kU);
  for (int k = 0; k < M::kControlHorizon; ++k)
    for (int i = 0; i < M::kU; ++i) p.direction(k * M::kU + i) = stab.first_direction(k, i);
  p.command.resize(M::kU);
  for (int i = 0; i < M::kU; ++i) p.command(i) = N::template to_real<M::kFracIn>(cmd[i]);
  p.alpha = stab.best_alpha();
  return p;
}

// The build's loss weights by the one rule (trainer/control/loss_weights.h):
// the model's profile groups and codegen's default rule, as the build
// generates its headers (HADYNET_CODEGEN_OPTIONS empty).
const trainer::control::LossWeights& rule_weights() {
  static const trainer::control::LossWeights w = [] {
    const HadynetModel& m = test::build_model();
    const auto classes = trainer::control::loss_classes(
        m.layout.y_names, {m.profile.force_groups, m.profile.angle_groups, m.profile.length_groups});
    return trainer::control::loss_weights(classes, m.norm.y.std, trainer::control::LossRule{});
  }();
  return w;
}

// The same optimiser on the trainer's double network (the reference,
// trainer/control/reference_stabiliser.h), with the firmware's settings.
Plan reference_plan(const LogSequence& s, int t, int t_ref, int epochs, int truncation) {
  const HadynetModel& m = test::build_model();
  static const trainer::HadynetParams<double> params = m.params.cast<double>();
  trainer::control::StabiliserSettings settings;
  settings.horizon = F::kControlHorizon;
  settings.epochs = epochs;
  settings.truncation = truncation;
  for (int a = 0; a < F::kControlAlphaCount; ++a) settings.alphas.push_back(static_cast<double>(F::kControlAlpha[a]));
  for (int i = 0; i < F::kU; ++i) settings.active.push_back(F::kControlActive[i]);
  trainer::control::StabiliserProblem problem;
  problem.x0 = m.norm.x.standardize(trainer::initial_state(m.layout, s, t));
  problem.pb = detection_pb();
  problem.y_now = m.norm.y.standardize(s.y.col(t));
  problem.y_ref = m.norm.y.standardize(s.y.col(t_ref));
  problem.hold = hold_command();
  return trainer::control::reference_plan(params, problem, rule_weights(), settings);
}

// The generated loss weights are the rule's, rounded once to float.
TEST(FirmwareRoundTrip, GeneratedLossWeightsFollowTheRule) {
  const trainer::control::LossWeights& w = rule_weights();
  for (int i = 0; i < F::kY; ++i) {
    EXPECT_EQ(F::kLossWeightUp[i], static_cast<float>(w.up(i))) << F::kYNames[i];
    EXPECT_EQ(F::kLossWeightDown[i], static_cast<float>(w.down(i))) << F::kYNames[i];
  }
}

double cosine(const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return a.dot(b) / (a.norm() * b.norm()); }

TEST(FirmwareRoundTrip, StabiliserGradientAndCommandMatchTrainer) {
  const LogSequence s = test::held_out_sequence("Cylinder", "random2");
  double min_cos_f = 1, min_cos_q = 1, max_cmd_f = 0, max_cmd_q = 0;
  int windows = 0, same_alpha_q = 0;
  for (int t = 12; t + 1 < s.steps(); t += 9) {
    const int t_ref = t - 6;  // reference: the state a little earlier (a drifted grasp)
    for (int truncation : {F::kControlHorizon, 2}) {
      const Plan ref1 = reference_plan(s, t, t_ref, 1, truncation);
      const Plan f1 = firmware_plan<F>(s, t, t_ref, 1, truncation);
      const Plan q1 = firmware_plan<Q>(s, t, t_ref, 1, truncation);
      min_cos_f = std::min(min_cos_f, cosine(ref1.direction, f1.direction));
      min_cos_q = std::min(min_cos_q, cosine(ref1.direction, q1.direction));
    }
    const Plan ref = reference_plan(s, t, t_ref, F::kControlEpochs, F::kControlTruncation);
    const Plan f = firmware_plan<F>(s, t, t_ref, F::kControlEpochs, F::kControlTruncation);
    const Plan q = firmware_plan<Q>(s, t, t_ref, F::kControlEpochs, F::kControlTruncation);
    max_cmd_f = std::max(max_cmd_f, (f.command - ref.command).cwiseAbs().maxCoeff());
    max_cmd_q = std::max(max_cmd_q, (q.command - ref.command).cwiseAbs().maxCoeff());
    same_alpha_q += q.alpha == ref.alpha ? 1 : 0;
    ++windows;
  }
  std::printf("%d windows: gradient cosine min f32 %.6f q15 %.6f; command max |diff| f32 %.3g q15 %.3g "
              "(standardised); q15 picked the reference's step size in %d\n",
              windows, min_cos_f, min_cos_q, max_cmd_f, max_cmd_q, same_alpha_q);
  EXPECT_GE(min_cos_f, test::tolerance("gradient.f32.cosine_min"));
  EXPECT_GE(min_cos_q, test::tolerance("gradient.q15.cosine_min"));
  EXPECT_LE(max_cmd_f, test::tolerance("command.f32.max"));
  EXPECT_LE(max_cmd_q, test::tolerance("command.q15.max"));
}

// ---- detection: the runtime against the trainer's detection_distances

template <class M>
std::vector<firmware::StepResult<M>> run_detect(const LogSequence& s) {
  auto rt = std::make_unique<firmware::HadynetRuntime<M>>();
  rt->set_mode(firmware::Mode::kDetect);
  std::vector<firmware::StepResult<M>> out;
  firmware::SensorFrame<M> f{};
  for (int t = 0; t < s.steps(); ++t) {
    frame<M>(s, t, f.y);
    for (int i = 0; i < M::kU; ++i) f.u_prev[i] = t == 0 ? 0.0f : static_cast<float>(s.u(i, t - 1));
    out.push_back(rt->step(f));
  }
  return out;
}

TEST(FirmwareRoundTrip, DetectionAgreesWithTrainer) {
  const HadynetModel& m = test::build_model();
  const int n = m.detection->steps;
  ASSERT_EQ(n, Q::kDetectSteps);
  const double c = m.detection->threshold;
  struct Case {
    const char* object;
    bool contact;
  };
  for (const Case& k : {Case{"None", false}, Case{"Cylinder", true}, Case{"Ball", true}, Case{"Hammer", true}}) {
    const LogSequence s = test::held_out_sequence(k.object, "random2");
    const Eigen::VectorXd d_ref = trainer::detection_distances(m, *m.detection, s);
    const auto q = run_detect<Q>(s);
    const auto f = run_detect<F>(s);
    double rel_q = 0, rel_f = 0;
    int agree = 0, flagged = 0, flagged_ref = 0;
    for (Eigen::Index j = 0; j < d_ref.size(); ++j) {
      const std::size_t t = static_cast<std::size_t>(j + 1 + n);
      ASSERT_TRUE(q[t].distance_valid && f[t].distance_valid) << "row " << t;
      const double floor = std::max(d_ref(j), 1.0);
      rel_f = std::max(rel_f, std::abs(f[t].d - d_ref(j)) / floor);
      // q15: the whitened error z is int16 in a format sized for |z| up to
      // 4 C_detect (codegen), so far inside contact d saturates; there only
      // the decision is checked (agreement below).
      if (d_ref(j) <= 2 * c) {
        rel_q = std::max(rel_q, std::abs(q[t].d - d_ref(j)) / floor);
      }
      agree += q[t].contact == (d_ref(j) > c) ? 1 : 0;
      flagged += q[t].contact ? 1 : 0;
      flagged_ref += d_ref(j) > c ? 1 : 0;
    }
    const double steps = static_cast<double>(d_ref.size());
    std::printf("%-9s d rel. error max f32 %.2g q15 %.2g (d <= 2 C_detect); q15 flags %.1f%% (trainer %.1f%%), decisions agree "
                "%.1f%%\n",
                k.object, rel_f, rel_q, 100 * flagged / steps, 100 * flagged_ref / steps, 100 * agree / steps);
    EXPECT_LE(rel_f, test::tolerance("detection.f32.d_rel"));
    EXPECT_LE(rel_q, test::tolerance("detection.q15.d_rel"));
    EXPECT_GE(agree / steps, test::tolerance("detection.q15.agreement_min"));
    if (k.contact) {
      EXPECT_GE(flagged / steps, test::tolerance("detection.grasp.flagged_min")) << k.object;
    } else {
      EXPECT_LE(flagged / steps, test::tolerance("detection.none.flagged_max")) << k.object;
    }
  }
}

}  // namespace
}  // namespace hadynet
