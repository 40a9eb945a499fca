// A model fixed by `hadynet residual --fix` through codegen and the firmware
// core (make_fixed_model.cc: derived inputs sign_u0 and hyst_u0, cross-talk,
// a load drift, a calibration curve and clips): the runtime's reported
// prediction on a held-out plant log must equal the trainer's measured-frame
// prediction of the same model (to_model_frame, the network, then the sensor
// model forward) within the forward tolerances of docs/tolerances.md; the
// derived inputs must be computed by the firmware (the frames carry garbage
// in their slots). The sensor stage alone (the curve beyond its end knots
// included) is checked against the trainer's transforms, and a model image
// of this model against its compiled-in tensors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>

#include "codegen/codegen.h"
#include "firmware/core/hadynet_runtime.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "host-sim/model_image/row_major_model.h"
#include "test/firmware/held_out_logs.h"
#include "test/firmware/tolerances.h"
#include "trainer/control/reference_stabiliser.h"
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
  EXPECT_EQ(F::kUDerivedBase[F::kU - 1], 3);
  EXPECT_EQ(F::kUDerivedLag[F::kU - 1], 2);
  EXPECT_EQ(F::kUDerivedLag[F::kU - 2], 0);
  EXPECT_FALSE(F::kControlActive[F::kU - 1]);  // never set by the stabiliser
  EXPECT_EQ(F::kCrosstalkCount, 1);
  EXPECT_EQ(F::kDriftCount, 1);
  EXPECT_EQ(F::kClipCount, 2);
  EXPECT_EQ(Q::kClipCount, 2);
  // fc2, a cross-talk target, has no frame rail: the type's extreme.
  EXPECT_EQ(Q::kClipRailModel[1], -32768);
  EXPECT_EQ(F::kClipRailModel[1], std::numeric_limits<float>::lowest());
  EXPECT_EQ(F::kSensorPeriod, 0.2f);
  ASSERT_EQ(m.sensor.curves.size(), 1u);
  const trainer::SensorCurve& curve = m.sensor.curves[0];
  ASSERT_EQ(F::kCurveCount, 1);
  ASSERT_EQ(Q::kCurveCount, 1);
  ASSERT_EQ(F::kCurveKnots, static_cast<int>(curve.level.size()));
  EXPECT_STREQ(F::kYNames[F::kCurveChannel[0]], curve.channel.c_str());
  for (int k = 0; k < F::kCurveKnots; ++k) {  // physical floats in both numerics
    EXPECT_EQ(F::kCurveLevel[k], static_cast<float>(curve.level[static_cast<std::size_t>(k)])) << k;
    EXPECT_EQ(F::kCurveReading[k], static_cast<float>(curve.reading[static_cast<std::size_t>(k)])) << k;
    EXPECT_EQ(Q::kCurveLevel[k], F::kCurveLevel[k]) << k;
    EXPECT_EQ(Q::kCurveReading[k], F::kCurveReading[k]) << k;
  }
}

Eigen::Index y_row(const trainer::HadynetModel& m, const std::string& name) {
  const auto& y = m.layout.y_names;
  return static_cast<Eigen::Index>(std::find(y.begin(), y.end(), name) - y.begin());
}

// The trainer's sensor model forward on model-frame values (physical, y x T;
// column t is row t of `table`): the curves (held_out.cc's order), cross-talk
// from the model-frame source, the drift with D(t) from the measured column,
// and the clips.
Eigen::MatrixXd sensor_forward(const trainer::HadynetModel& m, const Eigen::MatrixXd& model_frame,
                               const datalog::LogTable& table) {
  Eigen::MatrixXd out = model_frame;
  for (const auto& c : m.sensor.curves)
    for (Eigen::Index t = 0; t < out.cols(); ++t)
      out(y_row(m, c.channel), t) = trainer::curve_reading(c, model_frame(y_row(m, c.channel), t));
  for (const auto& x : m.sensor.crosstalk) out.row(y_row(m, x.target)) += x.gain * model_frame.row(y_row(m, x.source));
  for (const auto& d : m.sensor.drifts) {
    const std::vector<double> driver = trainer::drift_driver(table, "log", d);
    for (Eigen::Index t = 0; t < out.cols(); ++t) out(y_row(m, d.channel), t) += d.rate * driver[static_cast<std::size_t>(t)];
  }
  for (const auto& c : m.sensor.clips)
    out.row(y_row(m, c.channel)) = c.side > 0 ? out.row(y_row(m, c.channel)).cwiseMin(c.rail).eval()
                                              : out.row(y_row(m, c.channel)).cwiseMax(c.rail).eval();
  return out;
}

// The trainer's prediction of every measured row t >= 2 of `table`
// (physical, y x T; column t valid for t >= 2): the model-frame 1-step
// prediction (the runtime's N_detect is 1 without detection statistics),
// then the sensor model forward.
Eigen::MatrixXd trainer_measured(const trainer::HadynetModel& m, const datalog::LogTable& table,
                                 const Eigen::VectorXf& pb) {
  const datalog::LogTable frame_table = trainer::to_model_frame(m.sensor, table, "log");
  const trainer::LogSequence frame = trainer::log_sequence(frame_table, "log", m.layout);
  const Eigen::MatrixXd p = trainer::residual::predict_windows(m, frame, pb, 1);  // clips applied
  Eigen::MatrixXd model_frame = Eigen::MatrixXd::Zero(p.rows(), static_cast<Eigen::Index>(table.rows()));
  for (Eigen::Index b = 0; b < p.cols(); ++b) model_frame.col(b + 2) = p.col(b);
  return sensor_forward(m, model_frame, table);
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
  // fc3 in the model's frame visits both continuations of its curve (below
  // the first knot, beyond the last), so that both directions of the curve
  // are exercised there too.
  const auto& m = fixed_model();
  const trainer::SensorCurve& curve = m.sensor.curves.at(0);
  const datalog::LogTable frame = trainer::to_model_frame(m.sensor, table, "log");
  int below = 0, beyond = 0;
  for (std::size_t t = 0; t < frame.rows(); ++t) {
    const double v = frame.at(t, *frame.column_index(curve.channel));
    below += v < curve.level.front();
    beyond += v > curve.level.back();
  }
  EXPECT_GT(below, 0);
  EXPECT_GT(beyond, 0);
  // fc2 with fc3's pick-up removed goes below its rated floor in the frame,
  // where a frame clip at the measured rail (0 N) would differ.
  int fc2_negative = 0;
  for (std::size_t t = 0; t < frame.rows(); ++t) fc2_negative += frame.at(t, *frame.column_index("fc2")) < 0.0;
  EXPECT_GT(fc2_negative, 0);
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

TEST(FixedModelRuntime, ControlModeHoldsFrictionInputsAndFeedsTheLagInputTheCommandsSent) {
  const datalog::LogTable& table = test::held_out_table("Cylinder", "random2", 150);
  // u3 sent at row s: a ramp, so that one frame off reads another value.
  const auto u3_sent = [](std::size_t s) { return 0.1 * static_cast<double>(s + 1); };
  // Two LSBs of Q(kFracIn) in lag2_u3's physical units.
  const double lsb2 = 2.0 * fixed_model().norm.u.std(Q::kU - 1) / (1 << Q::kFracIn);
  auto rt = std::make_unique<firmware::HadynetRuntime<Q>>();
  rt->set_mode(firmware::Mode::kControl);
  for (std::size_t t = 0; t < 8; ++t) {
    firmware::SensorFrame<Q> f{};
    for (int i = 0; i < Q::kY; ++i) f.y[i] = static_cast<float>(table.at(t, *table.column_index(Q::kYNames[i])));
    f.u_prev[0] = -0.5f;  // u0 moved: sign_u0 = hyst_u0 = -1
    f.u_prev[3] = t == 0 ? 0.0f : static_cast<float>(u3_sent(t - 1));  // frame t carries u_{t-1}
    const auto r = rt->step(f);
    if (t < 1) continue;
    ASSERT_TRUE(r.command_valid) << t;
    // The friction inputs are reported at their held value (hyst_u0 -1, standardised back; u1
    // never changes: dhyst_u1 0).
    EXPECT_NEAR(r.command[Q::kU - 4], -1.0f, 0.01f) << t;
    EXPECT_NEAR(r.command[Q::kU - 2], 0.0f, 0.01f) << t;
    // lag2_u3 at the plan's step 0 (the command u_t) is u3 sent two steps earlier, u3_{t-2}
    // (0 before the first command); one frame off reads u3_{t-1} or u3_{t-3}, 0.1 away.
    const double want = t < 2 ? 0.0 : u3_sent(t - 2);
    EXPECT_NEAR(r.command[Q::kU - 1], want, lsb2) << t;
    for (float v : r.command) EXPECT_TRUE(std::isfinite(v));
  }
}

// ---- the sensor stage on its own: the curve on fc3 (with the drift and the
// cross-talk it sits behind) against the trainer's transforms

// Firmware (binary32) against trainer (double), physical units, relative to
// 1 + |value|: the inputs and knots are rounded to float and each of the
// stage's few operations per value rounds again (2^-24 each), the segment
// slopes are below 1.5, and the drift integral adds one rounding per row
// (60 rows here): together below 1e-6; 1e-5 leaves a margin of 10.
constexpr double kStageTolerance = 1e-5;

// The stage reports model-frame level v of channel c through `curve` (g, the
// trainer's curve_reading), for every v of `levels`.
template <class M, class Levels>
void expect_reads_through(const firmware::SensorStage<M>& stage, int c, const trainer::SensorCurve& curve,
                          const Levels& levels) {
  for (const double v : levels) {
    float y_prime[M::kY] = {}, y[M::kY];
    y_prime[c] = static_cast<float>(v);
    stage.to_measured(y_prime, y);
    const double want = trainer::curve_reading(curve, v);
    EXPECT_NEAR(y[c], want, kStageTolerance * (1 + std::abs(want))) << v;
  }
}

// The held-out log's first `rows` rows with the curve's channel replaced by a
// ramp from 1 (unit) below the curve's first reading knot to 1 beyond its
// last: the inverse curve is used on both continuations and every segment.
datalog::LogTable curve_sweep_table(const trainer::SensorCurve& curve, std::size_t rows) {
  datalog::LogTable t = test::held_out_table("Cylinder", "random2", 150);
  t.values.resize(rows * t.columns.size());
  const std::size_t c = *t.column_index(curve.channel);
  const double lo = curve.reading.front() - 1, hi = curve.reading.back() + 1;
  for (std::size_t r = 0; r < rows; ++r) t.at(r, c) = lo + (hi - lo) * static_cast<double>(r) / static_cast<double>(rows - 1);
  return t;
}

template <class M>
void expect_stage_as_the_trainer() {
  const auto& m = fixed_model();
  const trainer::SensorCurve& curve = m.sensor.curves.at(0);
  const datalog::LogTable table = curve_sweep_table(curve, 60);
  // Frame transform: drift removed, cross-talk removed, the curve inverted.
  const datalog::LogTable frame = trainer::to_model_frame(m.sensor, table, "log");
  ASSERT_EQ(frame.rows(), table.rows());
  // Output transform of those model-frame values: the curve, cross-talk, drift, clip.
  Eigen::MatrixXd model_frame(M::kY, static_cast<Eigen::Index>(table.rows()));
  for (int i = 0; i < M::kY; ++i)
    for (std::size_t t = 0; t < table.rows(); ++t)
      model_frame(i, static_cast<Eigen::Index>(t)) = frame.at(t, *frame.column_index(M::kYNames[i]));
  const Eigen::MatrixXd measured = sensor_forward(m, model_frame, table);

  const int fc3 = static_cast<int>(y_row(m, curve.channel));
  firmware::SensorStage<M> stage;
  stage.reset();
  double worst_frame = 0, worst_measured = 0;
  int below = 0, beyond = 0;
  for (std::size_t t = 0; t < table.rows(); ++t) {
    float y[M::kY], u_prev[M::kU] = {}, y_model[M::kY], u_model[M::kU], y_prime[M::kY], y_out[M::kY];
    for (int i = 0; i < M::kY; ++i) y[i] = static_cast<float>(table.at(t, *table.column_index(M::kYNames[i])));
    stage.to_model(y, u_prev, y_model, u_model);
    for (int i = 0; i < M::kY; ++i) {
      const double want = model_frame(i, static_cast<Eigen::Index>(t));
      worst_frame = std::max(worst_frame, std::abs(y_model[i] - want) / (1 + std::abs(want)));
      y_prime[i] = static_cast<float>(want);
    }
    below += y_prime[fc3] < curve.level.front();
    beyond += y_prime[fc3] > curve.level.back();
    stage.to_measured(y_prime, y_out);  // D as of this frame, as the trainer's column t
    for (int i = 0; i < M::kY; ++i) {
      const double want = measured(i, static_cast<Eigen::Index>(t));
      worst_measured = std::max(worst_measured, std::abs(y_out[i] - want) / (1 + std::abs(want)));
    }
  }
  std::printf("sensor stage vs trainer, largest |diff| / (1 + |value|): frame %.3g, measured %.3g "
              "(%d rows below the curve's first knot, %d beyond its last)\n",
              worst_frame, worst_measured, below, beyond);
  EXPECT_LE(worst_frame, kStageTolerance);
  EXPECT_LE(worst_measured, kStageTolerance);
  EXPECT_GT(below, 0);
  EXPECT_GT(beyond, 0);
  // g on its own (no drift yet after a reset; fc3 is no cross-talk target)
  // on a finer grid: at and between the knots and 2 N beyond both ends.
  stage.reset();
  std::vector<double> grid;
  for (double v = curve.level.front() - 2; v <= curve.level.back() + 2; v += 0.0625) grid.push_back(v);
  expect_reads_through(stage, fc3, curve, grid);
}

TEST(FixedModelSensorStage, CurveFrameAndOutputTransformsAreTheTrainersF32) { expect_stage_as_the_trainer<F>(); }
TEST(FixedModelSensorStage, CurveFrameAndOutputTransformsAreTheTrainersQ15) { expect_stage_as_the_trainer<Q>(); }

// ---- the fixed model as a model image: its curve knots are data

// The image's tensors of `model` for a firmware of shape M (as
// host-sim/model_image/model_image_writer.h builds them, without signing).
template <class M>
std::unique_ptr<firmware::ModelTensors<M>> image_tensors(const trainer::HadynetModel& model,
                                                         const codegen::ModelIdentity& identity) {
  codegen::CodegenOptions o;
  o.numeric = M::kNumeric;
  const codegen::GeneratedHeader h = codegen::generate(model, identity, o);
  EXPECT_EQ(h.shape_id, M::kShapeId) << "not the fixed firmware's shape";
  auto source = std::make_unique<host::RowMajorModel<M>>();
  source->read(h.literals);
  auto tensors = std::make_unique<firmware::ModelTensors<M>>();
  std::memset(static_cast<void*>(tensors.get()), 0, sizeof(firmware::ModelTensors<M>));
  firmware::build_tensors<M>(*source, *tensors);
  return tensors;
}

template <class M>
void expect_image_carries_the_curve() {
  if (std::string(HADYNET_CODEGEN_OPTIONS) != "") GTEST_SKIP() << "the build's codegen options are not the defaults";
  const codegen::LoadedModel loaded = codegen::load_model_file(HADYNET_FIXED_MODEL_PATH);
  const auto same = image_tensors<M>(loaded.model, loaded.identity);
  EXPECT_EQ(0, std::memcmp(same.get(), &firmware::kCompiledTensors<M>, sizeof(firmware::ModelTensors<M>)))
      << "the image's tensors differ from the compiled-in ones";
  // An update with a re-fitted curve (other knots, same shape) carries the
  // new knots, and a stage reading the image's tensors uses them.
  trainer::HadynetModel refitted = loaded.model;
  trainer::SensorCurve& curve = refitted.sensor.curves.at(0);
  for (double& r : curve.reading) r = 1.1 * r + 0.05;
  const auto updated = image_tensors<M>(refitted, loaded.identity);
  for (int k = 0; k < M::kCurveKnots; ++k)
    EXPECT_EQ(updated->curve_reading[k], static_cast<float>(curve.reading[static_cast<std::size_t>(k)])) << k;
  // Knots a sensor stage cannot use are refused (the self-test of an image
  // on trial, app/model_store.h): not increasing, or not finite.
  EXPECT_TRUE(firmware::curve_tensors_valid<M>(*updated));
  EXPECT_TRUE(firmware::curve_tensors_valid<M>(firmware::kCompiledTensors<M>));
  {
    auto bad = std::make_unique<firmware::ModelTensors<M>>(*updated);
    bad->curve_level[1] = bad->curve_level[0];
    EXPECT_FALSE(firmware::curve_tensors_valid<M>(*bad));
    *bad = *updated;
    bad->curve_reading[M::kCurveKnots - 1] = std::numeric_limits<float>::infinity();
    EXPECT_FALSE(firmware::curve_tensors_valid<M>(*bad));
    *bad = *updated;
    bad->curve_level[0] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(firmware::curve_tensors_valid<M>(*bad));
  }
  const firmware::SensorStage<M> stage(*updated);
  const int c = static_cast<int>(y_row(refitted, curve.channel));
  expect_reads_through(stage, c, curve,
                       std::vector<double>{curve.level.front() - 1, curve.level[1], curve.level.back() + 1});
}

TEST(FixedModelImage, CarriesTheCurveKnotsF32) { expect_image_carries_the_curve<F>(); }
TEST(FixedModelImage, CarriesTheCurveKnotsQ15) { expect_image_carries_the_curve<Q>(); }

// ---- the stabiliser through an input dead time: lag2_u3 is u3 two steps
// earlier, so a planned u3 (a stabiliser command) acts two steps later
// (grasp_stabilizer.h)

// One planning problem in standardised reals (the f32 boundary's values).
struct PlanProblem {
  std::vector<float> x, y_now, y_ref, pb, hold;
  float history[2] = {};  // lag2_u3 at horizon steps 0 and 1: u3 at t-2 and t-1
};

PlanProblem plan_problem(const datalog::LogTable& table, std::size_t t, std::size_t t_ref) {
  using B = firmware::Boundary<F>;
  const auto& m = fixed_model();
  const auto y_row = [&](std::size_t r, float (&out)[F::kY]) {
    for (int i = 0; i < F::kY; ++i) out[i] = static_cast<float>(table.at(r, *table.column_index(F::kYNames[i])));
  };
  float yt[F::kY], yp[F::kY], yr[F::kY], x[F::kX], y_now[F::kY], y_ref[F::kY], hold[F::kU];
  y_row(t, yt);
  y_row(t - 1, yp);
  y_row(t_ref, yr);
  B{}.x_from_frames(yt, yp, x);
  B{}.y_to_model(yt, y_now);
  B{}.y_to_model(yr, y_ref);
  const float zero[F::kU] = {};
  B{}.u_to_model(zero, hold);
  PlanProblem p;
  p.x.assign(x, x + F::kX);
  p.y_now.assign(y_now, y_now + F::kY);
  p.y_ref.assign(y_ref, y_ref + F::kY);
  p.hold.assign(hold, hold + F::kU);
  for (int i = 0; i < F::kPb; ++i) p.pb.push_back(m.params.pb(0, i));
  const std::size_t u3 = *table.column_index("u3");
  for (int k = 0; k < 2; ++k) p.history[k] = B{}.u_to_model(F::kU - 1, static_cast<float>(table.at(t - 2 + k, u3)));
  return p;
}

template <class M>
trainer::control::StabiliserPlan firmware_plan(const PlanProblem& p, int truncation) {
  using N = firmware::Numerics<M>;
  using Value = typename M::Value;
  static firmware::GraspStabilizer<M> stab;  // large: traces
  static firmware::HadynetNet<M> net;
  Value hold[M::kU], y_ref[M::kY], y_now[M::kY], x[M::kX], pb[M::kPb], cmd[M::kU];
  for (int i = 0; i < M::kU; ++i) hold[i] = N::template from_real<M::kFracIn>(p.hold[static_cast<std::size_t>(i)]);
  for (int i = 0; i < M::kY; ++i) {
    y_ref[i] = N::template from_real<M::kFracY>(p.y_ref[static_cast<std::size_t>(i)]);
    y_now[i] = N::template from_real<M::kFracY>(p.y_now[static_cast<std::size_t>(i)]);
  }
  for (int i = 0; i < M::kX; ++i) x[i] = N::template from_real<M::kFracIn>(p.x[static_cast<std::size_t>(i)]);
  for (int i = 0; i < M::kPb; ++i) pb[i] = N::template from_real<M::kFracIn>(p.pb[static_cast<std::size_t>(i)]);
  stab.reset(hold);
  stab.set_reference(y_ref);
  stab.settings().truncation = truncation;
  for (int k = 0; k < 2; ++k) stab.set_lag_history(M::kU - 1, k, N::template from_real<M::kFracIn>(p.history[k]));
  stab.plan(net, x, y_now, pb, cmd);
  trainer::control::StabiliserPlan out;
  out.direction.resize(M::kControlHorizon * M::kU);
  for (int k = 0; k < M::kControlHorizon; ++k)
    for (int i = 0; i < M::kU; ++i) out.direction(k * M::kU + i) = stab.first_direction(k, i);
  out.command.resize(M::kU);
  for (int i = 0; i < M::kU; ++i) out.command(i) = N::template to_real<M::kFracIn>(cmd[i]);
  out.alpha = stab.best_alpha();
  return out;
}

// The trainer's reference optimiser on the same problem.
trainer::control::StabiliserPlan reference_plan(const PlanProblem& p, int truncation) {
  const auto& m = fixed_model();
  static const trainer::HadynetParams<double> params = m.params.cast<double>();
  const auto vec = [](const std::vector<float>& v) {
    return Eigen::Map<const Eigen::VectorXf>(v.data(), static_cast<Eigen::Index>(v.size())).cast<double>().eval();
  };
  trainer::control::StabiliserSettings settings;
  settings.horizon = F::kControlHorizon;
  settings.epochs = F::kControlEpochs;
  settings.truncation = truncation;
  for (int a = 0; a < F::kControlAlphaCount; ++a) settings.alphas.push_back(F::kControlAlpha[a]);
  for (int i = 0; i < F::kU; ++i) settings.active.push_back(F::kControlActive[i]);
  trainer::control::LossWeights w;
  w.up.resize(F::kY);
  w.down.resize(F::kY);
  for (int i = 0; i < F::kY; ++i) {
    w.up(i) = F::kLossWeightUp[i];
    w.down(i) = F::kLossWeightDown[i];
  }
  trainer::control::StabiliserProblem problem;
  problem.x0 = vec(p.x);
  problem.pb = vec(p.pb);
  problem.y_now = vec(p.y_now);
  problem.y_ref = vec(p.y_ref);
  problem.hold = vec(p.hold);
  problem.lagged = trainer::control::lagged_inputs(m);
  for (auto& l : problem.lagged) {
    l.history.resize(2);
    l.history(0) = p.history[0];
    l.history(1) = p.history[1];
  }
  return trainer::control::reference_plan(params, problem, w, settings);
}

// 0 when either is zero (a missing gradient path must not read as agreement).
double cosine(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double n = a.norm() * b.norm();
  return n > 0 ? a.dot(b) / n : 0.0;
}

// The entries of command u of a step-major direction (k * kU + i), steps 0..H-1.
Eigen::VectorXd command_part(const Eigen::VectorXd& direction, int u) {
  Eigen::VectorXd out(F::kControlHorizon);
  for (int k = 0; k < F::kControlHorizon; ++k) out(k) = direction(k * F::kU + u);
  return out;
}

// u3 acts only through lag2_u3 (make_fixed_model.cc), so its whole gradient
// is the lag path: holding the lag input over the horizon (the rule before)
// gives u3 none, and the u3 part of the direction below is all that path.
TEST(FixedModelStabiliser, PlansThroughTheCommandDelayAsTheTrainer) {
  const auto lagged = trainer::control::lagged_inputs(fixed_model());
  ASSERT_EQ(lagged.size(), 1u);
  EXPECT_EQ(lagged[0].slot, F::kU - 1);
  EXPECT_EQ(lagged[0].base, 3);
  ASSERT_TRUE(F::kControlActive[3]);
  EXPECT_EQ(lagged[0].lag, 2);
  const int h = F::kControlHorizon;
  const datalog::LogTable& table = test::held_out_table("Cylinder", "random2", 150);
  double min_cos_f = 1, min_cos_q = 1, max_cmd_f = 0, max_cmd_q = 0, min_cos_u3_f = 1, min_cos_u3_q = 1;
  double min_u3_share = 1;
  int plans = 0;
  for (std::size_t t = 12; t + 1 < table.rows(); t += 9) {
    const PlanProblem p = plan_problem(table, t, t - 6);
    for (int truncation : {F::kControlTruncation, 2}) {  // full BPTT (the default) and truncated
      const auto ref = reference_plan(p, truncation);
      const auto f = firmware_plan<F>(p, truncation);
      const auto q = firmware_plan<Q>(p, truncation);
      min_cos_f = std::min(min_cos_f, cosine(ref.direction, f.direction));
      min_cos_q = std::min(min_cos_q, cosine(ref.direction, q.direction));
      max_cmd_f = std::max(max_cmd_f, (f.command - ref.command).cwiseAbs().maxCoeff());
      max_cmd_q = std::max(max_cmd_q, (q.command - ref.command).cwiseAbs().maxCoeff());
      const Eigen::VectorXd ref_u3 = command_part(ref.direction, 3);
      min_u3_share = std::min(min_u3_share, ref_u3.norm());
      min_cos_u3_f = std::min(min_cos_u3_f, cosine(ref_u3, command_part(f.direction, 3)));
      min_cos_u3_q = std::min(min_cos_u3_q, cosine(ref_u3, command_part(q.direction, 3)));
      // A u3 in the last 2 steps acts beyond the horizon: no gradient.
      for (int k = h - 2; k < h; ++k) {
        EXPECT_EQ(f.direction(k * F::kU + 3), 0.0) << t;
        EXPECT_EQ(q.direction(k * F::kU + 3), 0.0) << t;
      }
      // The lag input as used at step 0 is the command applied two steps ago.
      EXPECT_EQ(f.command(F::kU - 1), p.history[0]) << t;
      EXPECT_NEAR(q.command(F::kU - 1), p.history[0], 1.0 / (1 << Q::kFracIn)) << t;  // its rounding
      ++plans;
    }
  }
  std::printf("%d plans (truncation 8 and 2): gradient cosine min f32 %.6f q15 %.6f; command max |diff| "
              "f32 %.3g q15 %.3g (standardised); u3's part (all through lag2_u3): norm at least %.3g of the unit direction, "
              "cosine min f32 %.6f q15 %.6f\n",
              plans, min_cos_f, min_cos_q, max_cmd_f, max_cmd_q, min_u3_share, min_cos_u3_f, min_cos_u3_q);
  EXPECT_GE(min_cos_f, test::tolerance("gradient.f32.cosine_min"));
  EXPECT_GE(min_cos_q, test::tolerance("gradient.q15.cosine_min"));
  EXPECT_LE(max_cmd_f, test::tolerance("command.f32.max"));
  EXPECT_LE(max_cmd_q, test::tolerance("command.q15.max"));
  // The lag path itself, on its own: present, and in the same direction.
  EXPECT_GT(min_u3_share, 0.0);
  EXPECT_GE(min_cos_u3_f, test::tolerance("gradient.f32.cosine_min"));
  EXPECT_GE(min_cos_u3_q, test::tolerance("gradient.q15.cosine_min"));
}

}  // namespace
}  // namespace hadynet
