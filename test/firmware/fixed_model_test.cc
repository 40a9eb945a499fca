// A model fixed by `hadynet residual --fix` through codegen and the firmware
// core (make_fixed_model.cc: derived inputs sign_u0 and hyst_u0, cross-talk,
// a load drift and a clip): the runtime's reported prediction on a held-out
// plant log must equal the trainer's measured-frame prediction of the same
// model (to_model_frame, the network, then the sensor model forward) within
// the forward tolerances of docs/tolerances.md; the derived inputs must be
// computed by the firmware (the frames carry garbage in their slots).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "firmware/core/hadynet_runtime.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "test/firmware/held_out_logs.h"
#include "test/firmware/tolerances.h"
#include "trainer/derived_inputs.h"
#include "trainer/residual/residuals.h"

namespace hadynet {
namespace {

using Q = fixed_q15::Model;
using F = fixed_f32::Model;

const trainer::HadynetModel& fixed_model() {
  static const trainer::HadynetModel m = trainer::load_model(HADYNET_FIXED_MODEL_PATH);
  return m;
}

TEST(FixedModelHeader, CarriesTheDerivedInputsAndTheSensorModel) {
  const auto& m = fixed_model();
  ASSERT_EQ(F::kU, m.params.dims.u);
  EXPECT_EQ(F::kU, test::build_model().params.dims.u + 5);
  EXPECT_EQ(F::kUDerived[F::kU - 5], firmware::DerivedKind::kSign);
  EXPECT_EQ(F::kUDerived[F::kU - 4], firmware::DerivedKind::kHysteresis);
  EXPECT_EQ(F::kUDerivedBase[F::kU - 4], 0);
  EXPECT_EQ(F::kUDerived[F::kU - 3], firmware::DerivedKind::kChangeSign);
  EXPECT_EQ(F::kUDerived[F::kU - 2], firmware::DerivedKind::kChangeHysteresis);
  EXPECT_EQ(F::kUDerivedBase[F::kU - 2], 1);
  EXPECT_EQ(F::kUDerived[F::kU - 1], firmware::DerivedKind::kLag);
  EXPECT_EQ(F::kUDerivedBase[F::kU - 1], 2);
  EXPECT_EQ(F::kUDerivedLag[F::kU - 1], 2);
  EXPECT_EQ(F::kUDerivedLag[F::kU - 2], 0);
  EXPECT_FALSE(F::kControlActive[F::kU - 1]);  // never set by the stabiliser
  EXPECT_EQ(F::kCrosstalkCount, 1);
  EXPECT_EQ(F::kDriftCount, 1);
  EXPECT_EQ(F::kClipCount, 1);
  EXPECT_EQ(Q::kClipCount, 1);
  EXPECT_EQ(F::kSensorPeriod, 0.2f);
}

// The trainer's prediction of every measured row t >= 2 of `table`
// (physical, y x T; column t valid for t >= 2): the model-frame 1-step
// prediction (the runtime's N_detect is 1 without detection statistics),
// then cross-talk from the predicted source, the drift with D(t) from the
// measured column, and the clip.
Eigen::MatrixXd trainer_measured(const trainer::HadynetModel& m, const datalog::LogTable& table,
                                 const Eigen::VectorXf& pb) {
  const datalog::LogTable frame_table = trainer::to_model_frame(m.sensor, table, "log");
  const trainer::LogSequence frame = trainer::log_sequence(frame_table, "log", m.layout);
  const Eigen::MatrixXd p = trainer::residual::predict_windows(m, frame, pb, 1);  // clips applied
  const auto row = [&](const std::string& n) {
    return static_cast<Eigen::Index>(std::find(m.layout.y_names.begin(), m.layout.y_names.end(), n) -
                                     m.layout.y_names.begin());
  };
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(p.rows(), static_cast<Eigen::Index>(table.rows()));
  for (Eigen::Index b = 0; b < p.cols(); ++b) out.col(b + 2) = p.col(b);
  const Eigen::MatrixXd model_frame = out;
  for (const auto& x : m.sensor.crosstalk) out.row(row(x.target)) += x.gain * model_frame.row(row(x.source));
  for (const auto& d : m.sensor.drifts) {
    const std::vector<double> driver = trainer::drift_driver(table, "log", d);
    for (Eigen::Index t = 2; t < out.cols(); ++t) out(row(d.channel), t) += d.rate * driver[static_cast<std::size_t>(t)];
  }
  for (const auto& c : m.sensor.clips)
    out.row(row(c.channel)) = c.side > 0 ? out.row(row(c.channel)).cwiseMin(c.rail).eval()
                                         : out.row(row(c.channel)).cwiseMax(c.rail).eval();
  return out;
}

// Largest |firmware - trainer| per channel over the log, in standardised units.
template <class M>
double max_error(const datalog::LogTable& table) {
  const auto& m = fixed_model();
  const Eigen::VectorXf pb = m.params.pb.row(0).transpose();
  const Eigen::MatrixXd want = trainer_measured(m, table, pb);
  // The log's columns in the model's order; derived inputs are not in the log.
  std::vector<std::size_t> y_cols, u_cols;
  for (const auto& n : m.layout.y_names) y_cols.push_back(*table.column_index(n));
  for (const auto& n : m.layout.u_names)
    u_cols.push_back(trainer::parse_derived_input(n) ? static_cast<std::size_t>(-1) : *table.column_index(n));
  auto rt = std::make_unique<firmware::HadynetRuntime<M>>();
  rt->set_mode(firmware::Mode::kObserve);
  float pbf[M::kPb];
  for (int i = 0; i < M::kPb; ++i) pbf[i] = pb(i);
  rt->set_pb(pbf);
  double worst = 0;
  for (std::size_t t = 0; t < table.rows(); ++t) {
    firmware::SensorFrame<M> f;
    for (int i = 0; i < M::kY; ++i) f.y[i] = static_cast<float>(table.at(t, y_cols[static_cast<std::size_t>(i)]));
    for (int i = 0; i < M::kU; ++i) {
      const std::size_t c = u_cols[static_cast<std::size_t>(i)];
      // u_{t-1}; garbage in a derived input's slot: the firmware computes it.
      f.u_prev[i] = c == static_cast<std::size_t>(-1) ? 123.0f : (t == 0 ? 0.0f : static_cast<float>(table.at(t - 1, c)));
    }
    const auto r = rt->step(f);
    if (t < 2) continue;
    EXPECT_TRUE(r.prediction_valid) << t;
    for (int i = 0; i < M::kY; ++i) {
      const double e = std::abs(r.prediction[i] - want(i, static_cast<Eigen::Index>(t))) / m.norm.y.std(i);
      worst = std::max(worst, e);
    }
  }
  return worst;
}

TEST(FixedModelRuntime, PredictionEqualsTheTrainersMeasuredFramePrediction) {
  // A held-out Cylinder grasp (fc3 and fc6 loaded: the drift and the clip act).
  const datalog::LogTable& table = test::held_out_table("Cylinder", "random2", 150);
  const double f32 = max_error<F>(table), q15 = max_error<Q>(table);
  std::printf("fixed model, 1-step prediction vs trainer, max standardised error: f32 %.3g, q15 %.3g\n", f32, q15);
  EXPECT_LE(f32, test::tolerance("forward.f32.max"));
  EXPECT_LE(q15, test::tolerance("forward.q15.max"));
}

TEST(FixedModelRuntime, ResetRestartsTheDriftAndHysteresisStates) {
  // Two runs over the same frames with a reset in between give the same predictions.
  const datalog::LogTable& table = test::held_out_table("Cylinder", "random2", 150);
  auto rt = std::make_unique<firmware::HadynetRuntime<Q>>();
  rt->set_mode(firmware::Mode::kObserve);
  std::vector<float> first, second;
  for (int pass = 0; pass < 2; ++pass) {
    rt->reset();
    for (std::size_t t = 0; t < 40; ++t) {
      firmware::SensorFrame<Q> f{};
      for (int i = 0; i < Q::kY; ++i) f.y[i] = static_cast<float>(table.at(t, *table.column_index(Q::kYNames[i])));
      for (int i = 0; i < Q::kU; ++i)
        if (Q::kUDerived[i] == firmware::DerivedKind::kNone && t > 0)
          f.u_prev[i] = static_cast<float>(table.at(t - 1, *table.column_index(Q::kUNames[i])));
      const auto r = rt->step(f);
      (pass == 0 ? first : second).insert((pass == 0 ? first : second).end(), r.prediction, r.prediction + Q::kY);
    }
  }
  EXPECT_EQ(first, second);
}

TEST(FixedModelRuntime, ControlModeRunsWithDerivedInputsHeld) {
  const datalog::LogTable& table = test::held_out_table("Cylinder", "random2", 150);
  auto rt = std::make_unique<firmware::HadynetRuntime<Q>>();
  rt->set_mode(firmware::Mode::kControl);
  for (std::size_t t = 0; t < 6; ++t) {
    firmware::SensorFrame<Q> f{};
    for (int i = 0; i < Q::kY; ++i) f.y[i] = static_cast<float>(table.at(t, *table.column_index(Q::kYNames[i])));
    f.u_prev[0] = -0.5f;  // u0 moved: sign_u0 = hyst_u0 = -1
    const auto r = rt->step(f);
    if (t < 1) continue;
    ASSERT_TRUE(r.command_valid) << t;
    // The derived inputs are reported at their held value (hyst_u0 -1, standardised back; u1 never
    // changes: dhyst_u1 0; u2 is 0: lag2_u2 0).
    EXPECT_NEAR(r.command[Q::kU - 4], -1.0f, 0.01f) << t;
    EXPECT_NEAR(r.command[Q::kU - 2], 0.0f, 0.01f) << t;
    EXPECT_NEAR(r.command[Q::kU - 1], 0.0f, 0.01f) << t;
    for (float v : r.command) EXPECT_TRUE(std::isfinite(v));
  }
}

}  // namespace
}  // namespace hadynet
