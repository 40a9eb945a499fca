// The parts --fix builds on (docs/residual.md, "--fix"), against hand-computed
// answers: derived command channels, output clips (physical and on the
// training loss), and the sensor model's frame transforms (alignment,
// cross-talk and drift removal, calibration curves), and which candidate the
// decision tests. All exact: integer-valued or closed-form cases, tolerance
// 1e-12.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "trainer/derived_inputs.h"
#include "trainer/log_dataset.h"
#include "trainer/output_clip.h"
#include "trainer/residual/analysis.h"
#include "trainer/residual/augment.h"
#include "trainer/residual/drift_probe.h"
#include "trainer/residual/fine_tune.h"
#include "trainer/residual/sensor_readout.h"
#include "trainer/sensor_model.h"

namespace hadynet::test {
namespace {

using namespace trainer;

datalog::LogTable table(const std::vector<std::string>& columns, const std::vector<std::vector<double>>& rows) {
  datalog::LogTable t;
  t.columns = columns;
  for (const auto& r : rows) t.append_row(r);
  return t;
}

TEST(DerivedInputs, SignAndHysteresisOfACommand) {
  const auto t = table({"y0", "u0"}, {{0, 0}, {0, 0.5}, {0, 0}, {0, -2}, {0, 0}, {0, 0}, {0, 3}});
  EXPECT_EQ(*derived_input_column(t, "sign_u0"), (std::vector<double>{0, 1, 0, -1, 0, 0, 1}));
  // 0 before the first non-zero command, then the last non-zero command's sign.
  EXPECT_EQ(*derived_input_column(t, "hyst_u0"), (std::vector<double>{0, 1, 1, -1, -1, -1, 1}));
  EXPECT_FALSE(derived_input_column(t, "hyst_u7").has_value());  // no base column
  EXPECT_FALSE(derived_input_column(t, "u0").has_value());       // not a derived name
  EXPECT_FALSE(parse_derived_input("hyst_").has_value());
  const auto d = parse_derived_input("sign_u12");
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->base, "u12");
  EXPECT_EQ(derived_input_name(*d), "sign_u12");
}

TEST(DerivedInputs, SignAndHysteresisOfAnAbsoluteCommandsChange) {
  const auto t = table({"y0", "u0"}, {{0, 2}, {0, 2.5}, {0, 2.5}, {0, 1}, {0, 1}, {0, 1.5}});
  // 0 in the first row (no change yet), then the sign of u0(t) - u0(t-1).
  EXPECT_EQ(*derived_input_column(t, "dsign_u0"), (std::vector<double>{0, 1, 0, -1, 0, 1}));
  EXPECT_EQ(*derived_input_column(t, "dhyst_u0"), (std::vector<double>{0, 1, 1, -1, -1, 1}));
  const auto d = parse_derived_input("dhyst_u3");
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->kind, DerivedKind::kChangeHysteresis);
  EXPECT_EQ(d->base, "u3");
  EXPECT_EQ(derived_input_name(*d), "dhyst_u3");
  EXPECT_EQ(parse_derived_input("dsign_u3")->kind, DerivedKind::kChangeSign);
}

TEST(DerivedInputs, LagOfACommandIsTheCommandDStepsEarlier) {
  const auto t = table({"y0", "u0"}, {{0, 0.5}, {0, -1}, {0, 2}, {0, 0}, {0, 3}});
  // u0(t - 2), 0 in the first two rows (no command before the log).
  EXPECT_EQ(*derived_input_column(t, "lag2_u0"), (std::vector<double>{0, 0, 0.5, -1, 2}));
  EXPECT_EQ(*derived_input_column(t, "lag1_u0"), (std::vector<double>{0, 0.5, -1, 2, 0}));
  const auto d = parse_derived_input("lag12_u3");
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->kind, DerivedKind::kLag);
  EXPECT_EQ(d->lag, 12);
  EXPECT_EQ(d->base, "u3");
  EXPECT_EQ(derived_input_name(*d), "lag12_u3");
  // Not lag names: no digits, a leading zero, 0, above kMaxCommandLag, no base.
  for (const char* name : {"lag_u0", "lag02_u0", "lag0_u0", "lag21_u0", "lag2_", "lag2u0", "lagx_u0"})
    EXPECT_FALSE(parse_derived_input(name).has_value()) << name;
}

TEST(DerivedInputs, LogSequenceComputesTheMissingColumnOnly) {
  const auto t = table({"y0", "u0"}, {{1, 0}, {2, -1}, {3, 0}});
  const FeatureLayout layout = feature_layout_from_names({"y0"}, {"u0", "hyst_u0"}, {});
  const LogSequence s = log_sequence(t, "t.csv", layout);
  EXPECT_EQ(s.u.row(1), Eigen::RowVector3d(0, -1, -1));
  // A derived name of a missing base is still a missing column, named.
  const FeatureLayout bad = feature_layout_from_names({"y0"}, {"u0", "hyst_u3"}, {});
  try {
    log_sequence(t, "t.csv", bad);
    ADD_FAILURE() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("t.csv: no column 'hyst_u3'"), std::string::npos) << e.what();
  }
  // y channels are never derived.
  EXPECT_THROW(log_sequence(t, "t.csv", feature_layout_from_names({"sign_u0"}, {"u0"}, {})), std::runtime_error);
}

// The null's clean logs in a dead-time model's world (with_model_dead_time):
// each lagged command column is advanced by its largest lag, and every log
// loses the largest lag's rows, so that lag<d>_<c> on the moved log is the
// clean log's u_c: what a plant with d steps of dead time would have logged.
TEST(DerivedInputs, TheNullsLogsShowTheModelsInputDeadTime) {
  const auto t = table({"t", "y0", "u0", "u1"},
                       {{0, 1, 5, 50}, {1, 2, 6, 60}, {2, 3, 7, 70}, {3, 4, 8, 80}, {4, 5, 9, 90}, {5, 6, 10, 100}});
  HadynetModel m;
  m.layout = feature_layout_from_names({"y0"}, {"u0", "u1"}, {});
  const std::vector<residual::LogInput> clean = {{t, "clean.csv"}};
  // No lag input: unchanged.
  EXPECT_EQ(residual::with_model_dead_time(m, clean)[0].table.values, t.values);
  m.layout = feature_layout_from_names({"y0"}, {"u0", "u1", "lag2_u0", "lag1_u1", "lag1_u0"}, {});
  const auto moved = residual::with_model_dead_time(m, clean);
  ASSERT_EQ(moved.size(), 1u);
  EXPECT_EQ(moved[0].file, "clean.csv");
  EXPECT_EQ(moved[0].table.columns, t.columns);
  // u0 by 2 (its largest lag), u1 by 1; t and y0 stay; 2 rows lost.
  EXPECT_EQ(moved[0].table.values, (std::vector<double>{0, 1, 7, 60, 1, 2, 8, 70, 2, 3, 9, 80, 3, 4, 10, 90}));
  // From row 2 on, the lag input is the clean log's command of the same row.
  EXPECT_EQ(*derived_input_column(moved[0].table, "lag2_u0"), (std::vector<double>{0, 0, 7, 8}));
  // A log too short for the dead time, or without the lagged command: named.
  const std::vector<residual::LogInput> short_log = {{table({"y0", "u0", "u1"}, {{1, 5, 50}, {2, 6, 60}}), "short.csv"}};
  try {
    residual::with_model_dead_time(m, short_log);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("short.csv"), std::string::npos) << e.what();
  }
  const std::vector<residual::LogInput> no_u1 = {{table({"y0", "u0"}, {{1, 5}, {2, 6}, {3, 7}}), "no_u1.csv"}};
  EXPECT_THROW(residual::with_model_dead_time(m, no_u1), std::invalid_argument);
}

HadynetModel clip_model() {
  HadynetModel m;
  m.layout = feature_layout_from_names({"a0", "a1"}, {"u0"}, {});
  m.norm.y.mean.resize(2);
  m.norm.y.mean << 1.0, 0.0;
  m.norm.y.std.resize(2);
  m.norm.y.std << 2.0, 1.0;
  m.sensor.clips = {{"a0", 1, 3.0}, {"a1", -1, -0.5}};
  return m;
}

TEST(OutputClip, PhysicalAndStandardisedAgree) {
  const HadynetModel m = clip_model();
  Eigen::MatrixXd y(2, 3);
  y << 2.0, 3.5, 10.0, -1.0, 0.0, -0.5;
  apply_output_clips(m, y);
  Eigen::MatrixXd want(2, 3);
  want << 2.0, 3.0, 3.0, -0.5, 0.0, -0.5;
  EXPECT_EQ(y, want);
  // Standardised: a0's rail (3 - 1) / 2 = 1, a1's -0.5; clipped elements have
  // no gradient.
  Matrix<float> s(2, 3), grad = Matrix<float>::Ones(2, 3);
  s << 0.5f, 1.25f, 4.5f, -1.0f, 0.0f, -0.5f;
  EXPECT_EQ(clip_standardised(m, s, &grad), 3);
  Matrix<float> want_s(2, 3), want_g(2, 3);
  want_s << 0.5f, 1.0f, 1.0f, -0.5f, 0.0f, -0.5f;
  want_g << 1, 0, 0, 0, 1, 1;  // exactly at the rail: not clipped
  EXPECT_EQ(s, want_s);
  EXPECT_EQ(grad, want_g);
}

// A clip bounds the measured channel; on the network's channel it is the
// rail only where the measured value follows from that channel alone
// (frame_rail, sensor_model.h). a0 picks up 0.5 a3, a1 drifts, a2 reads
// through g(x) = 1 + 2x, a3 is plain; each has a rated range [0, 1].
TEST(OutputClip, TheFrameHasARailOnlyWhereTheMeasuredChannelFollowsFromItAlone) {
  HadynetModel m;
  m.layout = feature_layout_from_names({"a0", "a1", "a2", "a3"}, {"u0"}, {});
  m.norm.y.mean = Eigen::VectorXd::Zero(4);
  m.norm.y.std = Eigen::VectorXd::Ones(4);
  m.sensor.crosstalk = {{"a0", "a3", 0.5}};
  m.sensor.drifts = {{"a1", true, 0.01}};
  m.sensor.curves = {{"a2", {0.0, 2.0}, {1.0, 5.0}}};
  for (const char* c : {"a0", "a1", "a2", "a3"}) {
    m.sensor.clips.push_back({c, -1, 0.0});
    m.sensor.clips.push_back({c, 1, 1.0});
  }
  EXPECT_FALSE(frame_rail(m.sensor, m.sensor.clips[0]));  // a0 = a0' + 0.5 a3': a0' < 0 is a reading of 0.5 a3' - |a0'|
  EXPECT_FALSE(frame_rail(m.sensor, m.sensor.clips[3]));  // a1 = a1' + a bias
  EXPECT_DOUBLE_EQ(*frame_rail(m.sensor, m.sensor.clips[4]), -0.5);  // g^-1(0), beyond the knots
  EXPECT_DOUBLE_EQ(*frame_rail(m.sensor, m.sensor.clips[5]), 0.0);   // g^-1(1)
  EXPECT_DOUBLE_EQ(*frame_rail(m.sensor, m.sensor.clips[7]), 1.0);
  SensorModel curved_target = m.sensor;  // a curve does not give a cross-talk target a rail
  curved_target.curves.push_back({"a0", {0.0, 1.0}, {0.0, 2.0}});
  EXPECT_FALSE(frame_rail(curved_target, m.sensor.clips[1]));
  EXPECT_TRUE(frame_transforms(m.sensor, "a0") && frame_transforms(m.sensor, "a1") && frame_transforms(m.sensor, "a2"));
  EXPECT_FALSE(frame_transforms(m.sensor, "a3"));

  Eigen::MatrixXd y(4, 2);
  y << -0.8, 1.6, -0.8, 1.6, -0.8, 1.6, -0.8, 1.6;
  Matrix<float> s = y.cast<float>(), grad = Matrix<float>::Ones(4, 2);
  apply_output_clips(m, y);
  Eigen::MatrixXd want(4, 2);
  want << -0.8, 1.6, -0.8, 1.6, -0.5, 0.0, 0.0, 1.0;
  EXPECT_EQ(y, want);
  EXPECT_EQ(clip_standardised(m, s, &grad), 4);  // a2 and a3 only
  EXPECT_EQ(s, want.cast<float>());
  EXPECT_EQ(grad.topRows(2), (Matrix<float>::Ones(2, 2)));
  EXPECT_EQ(grad.bottomRows(2), (Matrix<float>::Zero(2, 2)));
  EXPECT_EQ(standardised_clips(m).size(), 4u);
}

datalog::LogTable drift_log() {
  datalog::LogTable t = table({"fc0", "fc1", "u0"}, {{1, 5, 0}, {-2, 5, 0}, {3, 5, 0}, {0, 5, 0}});
  t.metadata.set("dt_s", "0.5");
  return t;
}

TEST(SensorFrame, DriftDriverAndRemoval) {
  const datalog::LogTable in = drift_log();
  // Load: the level accumulated, the reading less its bias b = rate D:
  // D_r = D_r-1 + dt (|fc0_r| - rate D_r), |fc0| = 1, 2, 3, 0, dt 0.5, rate
  // 0.1 (stop 53's driver, the reading alone, gave 0.5, 1.5, 3.0, 3.0).
  const std::vector<double> load = drift_driver(in, "d.csv", {"fc0", true, 0.1});
  const double magnitude[] = {1, 2, 3, 0};
  ASSERT_EQ(load.size(), 4u);
  for (std::size_t r = 0; r < 4; ++r)
    EXPECT_NEAR(load[r], (r ? load[r - 1] : 0.0) + 0.5 * (magnitude[r] - 0.1 * load[r]), 1e-12) << r;
  EXPECT_NEAR(load[0], 0.5 / 1.05, 1e-12);
  EXPECT_NEAR(load[3], (((0.5 / 1.05 + 1.0) / 1.05 + 1.5) / 1.05) / 1.05, 1e-12);
  // Time: t dt.
  EXPECT_EQ(drift_driver(in, "d.csv", {"fc0", false, 0.1}), (std::vector<double>{0.0, 0.5, 1.0, 1.5}));
  const auto out = drift_removed(in, "d.csv", {{"fc0", true, 0.1}, {"fc1", false, 2.0}});
  const double want0[] = {1 - 0.1 * load[0], -2 - 0.1 * load[1], 3 - 0.1 * load[2], 0 - 0.1 * load[3]};
  const double want1[] = {5, 4, 3, 2};
  for (std::size_t r = 0; r < 4; ++r) {
    EXPECT_NEAR(out.at(r, 0), want0[r], 1e-12);
    EXPECT_NEAR(out.at(r, 1), want1[r], 1e-12);
  }
  EXPECT_EQ(in.at(0, 0), 1);  // the input is untouched
  datalog::LogTable bad = in;
  bad.metadata.set("dt_s", "fast");
  try {
    drift_driver(bad, "d.csv", {"fc0", true, 0.1});
    ADD_FAILURE() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("d.csv:1: metadata 'dt_s': expected a number of seconds from 1e-09 to 1e+06, got 'fast'"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(drift_removed(in, "d.csv", {{"fc9", true, 0.1}}), std::runtime_error);
}

TEST(SensorFrame, AlignmentCrosstalkAndTheWholeFrame) {
  const datalog::LogTable in = drift_log();
  const auto aligned = time_aligned(in, "d.csv", {{"fc0", 2}});
  ASSERT_EQ(aligned.rows(), 2u);
  EXPECT_EQ(aligned.at(0, 0), 3);  // fc0 two rows earlier
  EXPECT_EQ(aligned.at(1, 0), 0);
  EXPECT_EQ(aligned.at(1, 1), 5);  // fc1 unchanged
  EXPECT_THROW(time_aligned(in, "d.csv", {{"fc0", 4}}), std::runtime_error);
  const auto both = time_aligned(in, "d.csv", {{"fc0", 2}, {"fc1", 1}});  // per-channel delays
  ASSERT_EQ(both.rows(), 2u);
  EXPECT_EQ(both.at(0, 0), 3);
  EXPECT_EQ(both.at(0, 1), 5);
  EXPECT_EQ(both.at(1, 2), 0);  // u0 of row 1
  const auto removed = crosstalk_removed(in, "d.csv", {{"fc0", "fc1", 0.2}});
  EXPECT_NEAR(removed.at(1, 0), -3.0, 1e-12);
  // The whole frame: drift (from the measured fc0), then cross-talk, then the delay.
  SensorModel s;
  s.drifts = {{"fc0", true, 0.1}};
  s.period_s = 0.5;
  s.crosstalk = {{"fc0", "fc1", 0.2}};
  s.delays = {{"fc0", 1}};
  const auto frame = to_model_frame(s, in, "d.csv");
  ASSERT_EQ(frame.rows(), 3u);
  const std::vector<double> load = drift_driver(in, "d.csv", s.drifts.front());
  EXPECT_NEAR(frame.at(0, 0), -2 - 0.1 * load[1] - 1.0, 1e-12);  // row 1's fc0, shifted to row 0
  EXPECT_NEAR(frame.at(2, 0), 0 - 0.1 * load[3] - 1.0, 1e-12);
  EXPECT_EQ(frame.at(2, 1), 5);
  // Every part checked against the channels.
  EXPECT_NO_THROW(s.check({"fc0", "fc1"}));
  EXPECT_THROW(s.check({"fc1"}), std::invalid_argument);
  EXPECT_EQ(s.describe().size(), 3u);
  EXPECT_TRUE(SensorModel{}.empty());
  EXPECT_EQ(to_model_frame(SensorModel{}, in, "d.csv").values, in.values);
}

// The fine-tuning loss read through a curve: a curved channel's element
// weighs g'(level)^2 at its level (model's frame), every other element 1;
// no curve, no weights.
TEST(SensorFrame, TheFineTuningLossOfACurvedChannelIsItsReadingsLoss) {
  trainer::LogSequence seq;
  seq.y.resize(2, 4);
  seq.y << 0.5, 1.0, 2.0, 4.0,  // fc0: curved
      0.5, 1.0, 2.0, 4.0;       // fc1
  SensorModel s;
  EXPECT_TRUE(residual::reading_loss_weights(s, {"fc0", "fc1"}, {seq}).empty());
  s.curves = {SensorCurve{"fc0", {0, 1, 3}, {0, 2, 3}}};
  const std::vector<Eigen::MatrixXd> w = residual::reading_loss_weights(s, {"fc0", "fc1"}, {seq, seq});
  ASSERT_EQ(w.size(), 2U);
  Eigen::MatrixXd want(2, 4);
  want << 4, 0.25, 0.25, 0.25, 1, 1, 1, 1;
  EXPECT_EQ(w[0], want);
  EXPECT_EQ(w[1], want);
}

// g through (0, 0), (1, 2), (3, 3): slope 2 on [0, 1], 1/2 on [1, 3],
// continued along the end segments.
TEST(SensorFrame, ACalibrationCurveAndItsInverse) {
  const SensorCurve g{"fc0", {0, 1, 3}, {0, 2, 3}};
  EXPECT_NEAR(curve_reading(g, 0.5), 1.0, 1e-12);
  EXPECT_NEAR(curve_reading(g, 2.0), 2.5, 1e-12);
  EXPECT_NEAR(curve_reading(g, -1.0), -2.0, 1e-12);  // below: the first segment's slope
  EXPECT_NEAR(curve_reading(g, 5.0), 4.0, 1e-12);    // above: the last's
  for (double v : {-2.0, 0.0, 0.25, 1.0, 2.9, 3.0, 7.5}) EXPECT_NEAR(curve_level(g, curve_reading(g, v)), v, 1e-12) << v;
  // Its slope: a knot belongs to the segment above it; beyond, the end segments'.
  EXPECT_EQ(curve_slope(g, -1.0), 2.0);
  EXPECT_EQ(curve_slope(g, 0.0), 2.0);
  EXPECT_EQ(curve_slope(g, 0.5), 2.0);
  EXPECT_EQ(curve_slope(g, 1.0), 0.5);
  EXPECT_EQ(curve_slope(g, 3.0), 0.5);
  EXPECT_EQ(curve_slope(g, 9.0), 0.5);
  // In the frame: drift and cross-talk removed first, then the curve inverted.
  const datalog::LogTable in = drift_log();  // fc0: 1, -2, 3, 0
  SensorModel s;
  s.curves = {g};
  const auto frame = to_model_frame(s, in, "d.csv");
  const double want[] = {0.5, -1.0, 3.0, 0.0};
  for (std::size_t r = 0; r < 4; ++r) EXPECT_NEAR(frame.at(r, 0), want[r], 1e-12) << r;
  EXPECT_EQ(frame.at(1, 1), in.at(1, 1));
  EXPECT_FALSE(s.frame_is_measured());
  EXPECT_EQ(s.curve_of("fc0"), &s.curves[0]);
  EXPECT_EQ(s.curve_of("fc1"), nullptr);
  EXPECT_NO_THROW(s.check({"fc0", "fc1"}));
  // Every part at once, a curved cross-talk source included: the sensor
  // model's forward direction, y_0 = g(y'_0) + 0.2 y'_1 + 0.1 D_0 and
  // y_1 = h(y'_1), gives the log back from its frame.
  SensorModel all;
  const SensorCurve h{"fc1", {0, 10}, {0, 5}};
  all.curves = {g, h};
  all.crosstalk = {{"fc0", "fc1", 0.2}};
  all.drifts = {{"fc0", true, 0.1}};
  all.period_s = 0.5;
  const auto both = to_model_frame(all, in, "d.csv");
  const std::vector<double> load = drift_driver(in, "d.csv", all.drifts[0]);
  for (std::size_t r = 0; r < 4; ++r) {
    EXPECT_NEAR(both.at(r, 1), 10.0, 1e-12) << r;  // h^-1(5)
    EXPECT_NEAR(curve_reading(g, both.at(r, 0)) + 0.2 * both.at(r, 1) + 0.1 * load[r], in.at(r, 0), 1e-12) << r;
    EXPECT_NEAR(curve_reading(h, both.at(r, 1)), in.at(r, 1), 1e-12) << r;
  }
  // Not increasing, too few knots, two on one channel: rejected, naming the channel.
  const std::vector<std::vector<SensorCurve>> invalid = {
      {{"fc0", {0, 1, 3}, {0, 2, 2}}}, {{"fc0", {0, 0, 3}, {0, 1, 2}}}, {{"fc0", {0}, {0}}}, {g, g}};
  for (const auto& curves : invalid) {
    SensorModel bad;
    bad.curves = curves;
    try {
      bad.check({"fc0"});
      ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("fc0"), std::string::npos) << e.what();
    }
  }
}

// SensorReadout reads a log's own frame back as the log: a delayed
// cross-talk source is read at its own delay (the measured source of the
// target's row, which crosstalk_removed() subtracts), a delayed target at
// its, through the source's curve into the frame and out of the target's,
// with a drift with time. Reading the source at the largest delay, as
// held_out_error did before stop 81, gives fc0 off by 0.3 times the
// source's change over a row. Rows whose frame rows are missing read NaN.
TEST(SensorReadout, ReadsALogsFrameBackAsTheLog) {
  datalog::LogTable in = table({"fc0", "fc1", "fc2", "u0"}, {{1, 5, 0.5, 0},
                                                            {-2, 6, 1, 0},
                                                            {3, 8, 1.5, 0},
                                                            {0, 7, 0.5, 0},
                                                            {4, 9, 2, 0},
                                                            {2, 4, 1, 0},
                                                            {1, 3, 0, 0},
                                                            {5, 6, 3, 0}});
  in.metadata.set("dt_s", "0.5");
  SensorModel s;
  s.delays = {{"fc0", 2}, {"fc1", 1}};
  s.crosstalk = {{"fc0", "fc1", 0.3}};
  s.curves = {{"fc1", {0, 4, 20}, {0, 6, 12}}};
  s.drifts = {{"fc2", false, 0.2}};
  s.period_s = 0.5;
  const datalog::LogTable frame = to_model_frame(s, in, "d.csv");
  ASSERT_EQ(frame.rows(), 6u);
  const residual::LogInput log{in, "d.csv"};
  const std::vector<std::string> y_names = {"fc0", "fc1", "fc2"};
  const residual::SensorReadout readout(y_names, s, log);
  EXPECT_EQ(readout.max_delay(), 2);
  const auto from_frame = [&](Eigen::Index c, int r) {
    if (r < 0 || r >= static_cast<int>(frame.rows())) return std::nan("");
    return frame.at(static_cast<std::size_t>(r), static_cast<std::size_t>(c));
  };
  // Rows 2..5: every frame row they read exists (fc2, not delayed, reads frame row t).
  for (int t = 2; t <= 5; ++t) {
    const Eigen::VectorXd v = readout.row(from_frame, t);
    for (Eigen::Index c = 0; c < 3; ++c) {
      const double measured = in.at(static_cast<std::size_t>(t), static_cast<std::size_t>(c));
      EXPECT_NEAR(v(c), measured, 1e-12) << y_names[static_cast<std::size_t>(c)] << " row " << t;
    }
  }
  // Row 6: fc2 would read frame row 6, which the frame (6 rows) lacks; fc0 and fc1 read rows 4 and 5.
  const Eigen::VectorXd last = readout.row(from_frame, 6);
  EXPECT_TRUE(std::isnan(last(2)));
  EXPECT_NEAR(last(0), in.at(6, 0), 1e-12);
  // The source read at the largest delay instead: fc0 is off.
  const auto source_late = [&](Eigen::Index c, int r) { return from_frame(c, c == 1 && r == 4 - 1 ? r - 1 : r); };
  EXPECT_GT(std::abs(readout.row(source_late, 4)(0) - in.at(4, 0)), 0.1);
  // A channel the model does not have.
  SensorModel unknown = s;
  unknown.crosstalk = {{"fc0", "fc9", 0.3}};
  EXPECT_THROW(residual::SensorReadout(y_names, unknown, log), std::logic_error);
}

// Which candidate the decision tests: the first, in the screen's order,
// whose gain over fine-tuning alone on the selection's rows is significant;
// else the clearest gain (the largest positive Diebold-Mariano statistic),
// not the screen's first, which on fresh logs is often the model's own
// misfit (docs/residual-experiments.md, "Detection on fresh logs"); not judged or no
// gain: the screen's first.
// The plan's curves are fitted as one (CalibrationCurves::refine): on the
// union of the channels' knots, by coordinate search from the identity. A
// faked probe of the unchanged network: every channel's error is 1 except
// a third channel's, 1 + the squared distance of fc0's readings at its knots
// from twice the level, so the loss is least at slope 2 on every segment,
// which the search's factor 2 reaches from the identity in one sweep.
TEST(SensorFrame, ThePlansCurvesAreFittedAsOneOnTheUnionOfTheirKnots) {
  residual::Augmentation a;
  a.kind = residual::EffectKind::kSensorCurve;
  a.channels = {"fc0", "fc1"};
  auto& change = a.change.emplace<residual::CalibrationCurves>();
  change.curves = {{"fc0", {0, 1, 2}, {0, 1, 2}}, {"fc1", {0, 1.5, 3}, {0, 1.5, 3}}};
  residual::TrainingRmse rmse;
  rmse.y_names = {"fc0", "fc1", "l0"};
  rmse.all = [](const SensorModel& s) {
    Eigen::VectorXd e = Eigen::VectorXd::Ones(3);
    if (const SensorCurve* c = s.curve_of("fc0"))
      for (std::size_t k = 0; k < c->level.size(); ++k) e(2) += std::pow(c->reading[k] - 2 * c->level[k], 2);
    return e;
  };
  std::vector<double> fitted;
  change.refine(a, SensorModel{}, rmse, fitted);
  ASSERT_EQ(change.curves.size(), 2u);
  const std::vector<double> knots = {0, 1, 1.5, 2, 3};
  for (const SensorCurve& c : change.curves) {
    ASSERT_EQ(c.level, knots) << c.channel;
    for (std::size_t k = 0; k < knots.size(); ++k) EXPECT_NEAR(c.reading[k], 2 * knots[k], 1e-12) << c.channel << k;
  }
  EXPECT_EQ(change.curves[0].channel, "fc0");
  EXPECT_EQ(change.curves[1].channel, "fc1");
  EXPECT_TRUE(fitted.empty());
  EXPECT_NE(a.description.find("one curve, 5 knots"), std::string::npos) << a.description;
}

// The curve's criterion is the unchanged network's error over windows of
// its N_train steps when the probe has it (TrainingRmse::windows), not its
// 1-step error: a faked probe whose 1-step error is least at the identity
// and whose windows' error is least at slope 2 gives a curve reading twice
// the level with the windows and the identity without them.
TEST(SensorFrame, TheCurveIsFittedOnTheWindowsError) {
  const auto fitted_readings = [](bool with_windows) {
    residual::Augmentation a;
    a.kind = residual::EffectKind::kSensorCurve;
    a.channels = {"fc0"};
    auto& change = a.change.emplace<residual::CalibrationCurves>();
    change.curves = {{"fc0", {0, 1, 2}, {0, 1, 2}}};
    // 1 + the squared distance of fc0's readings at its knots from `scale` times the level.
    const auto error_least_at = [](double scale) {
      return [scale](const SensorModel& s) {
        Eigen::VectorXd e = Eigen::VectorXd::Ones(2);
        if (const SensorCurve* c = s.curve_of("fc0"))
          for (std::size_t k = 0; k < c->level.size(); ++k) e(1) += std::pow(c->reading[k] - scale * c->level[k], 2);
        return e;
      };
    };
    residual::TrainingRmse rmse;
    rmse.y_names = {"fc0", "l0"};
    rmse.all = error_least_at(1);
    if (with_windows) rmse.windows = error_least_at(2);
    std::vector<double> fitted;
    change.refine(a, SensorModel{}, rmse, fitted);
    return change.curves.front().reading;
  };
  const std::vector<double> windows = fitted_readings(true), one_step = fitted_readings(false);
  ASSERT_EQ(windows.size(), 3u);
  ASSERT_EQ(one_step.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(windows[k], 2.0 * static_cast<double>(k), 1e-12) << k;
    EXPECT_NEAR(one_step[k], static_cast<double>(k), 1e-12) << k;
  }
}

// The curve bends one way (CalibrationCurves::refine): its segment slopes
// are fitted non-increasing (compressive) and non-decreasing (expansive),
// and the lower loss is kept. A faked probe of the unchanged network whose
// loss is the squared distance of fc0's readings at its knots from a
// target: a compressive target (slopes 2, 1, 0.5, 0.5) is reached with
// slopes in order and called compressive; a target that zigzags (slopes 2, 0.5, 2, 0.5),
// which a search without the order would reach, gives slopes in order.
TEST(SensorFrame, TheCurveBendsOneWay) {
  const auto fitted_slopes = [](const std::vector<double>& target_slopes, std::string* description) {
    residual::Augmentation a;
    a.kind = residual::EffectKind::kSensorCurve;
    a.channels = {"fc0"};
    auto& change = a.change.emplace<residual::CalibrationCurves>();
    change.curves = {{"fc0", {0, 1, 2, 3, 4}, {0, 1, 2, 3, 4}}};
    std::vector<double> target = {0};
    for (double s : target_slopes) target.push_back(target.back() + s);
    residual::TrainingRmse rmse;
    rmse.y_names = {"fc0", "l0"};
    rmse.all = [target](const SensorModel& s) {
      Eigen::VectorXd e = Eigen::VectorXd::Ones(2);
      if (const SensorCurve* c = s.curve_of("fc0"))
        for (std::size_t k = 0; k < c->level.size(); ++k) e(1) += std::pow(c->reading[k] - target[k], 2);
      return e;
    };
    std::vector<double> fitted;
    change.refine(a, SensorModel{}, rmse, fitted);
    const SensorCurve& c = change.curves.front();
    std::vector<double> slopes;
    for (std::size_t k = 1; k < c.level.size(); ++k)
      slopes.push_back((c.reading[k] - c.reading[k - 1]) / (c.level[k] - c.level[k - 1]));
    if (description != nullptr) *description = a.description;
    return slopes;
  };
  std::string description;
  const std::vector<double> compressive = fitted_slopes({2, 1, 0.5, 0.5}, &description);
  ASSERT_EQ(compressive.size(), 4u);
  // Near the target at every knot: the coordinate search moves one slope
  // at a time by factors of 0.5..2 for at most 6 sweeps, and a reading sums
  // every slope below it, so it stops near the minimum, not on it.
  const std::vector<double> target = {2, 3, 3.5, 4};  // readings at knots 1..4
  double reading = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    reading += compressive[k];
    EXPECT_NEAR(reading, target[k], 0.15) << k;
    if (k > 0) {
      EXPECT_LE(compressive[k], compressive[k - 1] + 1e-9) << k;
    }
  }
  EXPECT_NE(description.find("(compressive)"), std::string::npos) << description;
  const std::vector<double> zigzag = fitted_slopes({2, 0.5, 2, 0.5}, nullptr);
  ASSERT_EQ(zigzag.size(), 4u);
  bool non_increasing = true, non_decreasing = true;  // up to the readings' rounding
  for (std::size_t k = 1; k < zigzag.size(); ++k) {
    non_increasing = non_increasing && zigzag[k] <= zigzag[k - 1] + 1e-9;
    non_decreasing = non_decreasing && zigzag[k] >= zigzag[k - 1] - 1e-9;
  }
  EXPECT_TRUE(non_increasing || non_decreasing) << zigzag[0] << " " << zigzag[1] << " " << zigzag[2] << " " << zigzag[3];
}

// With a rated top above its knots (CalibrationCurves::rated_top) the
// curve ends there reading its own level, and the segment up to it keeps
// the order. A faked probe of the unchanged network whose loss is the
// squared distance of fc0's readings at its knots 1..4 from a compressive
// target that dips at the top knot (slopes 2, 1, 0.9, then 0.3: the fit's
// top segment on a few rows of one grasp's peak, stop 78). Without the
// rated top the fit follows the dip; with it at 8 the segment from knot 4
// to 8 may be no steeper than the one before, so the top knot reads at
// least 8 - 4 s3 (s3 the fitted slope below it) and stays near the body's
// line, above the unanchored reading. A target whose top segment is flat
// (slope 0.1, the fit at its slope bound 1/4) where the group's channels
// top out together (two of three within 5 % of the span: a rail's
// signature) keeps the fit without the rated top, whose flat end the
// rail's simpler account reads (flat_at_end); where one channel alone
// reaches the top (one grasp's peak) it ends at the rated top.
TEST(SensorFrame, TheCurveEndsAtTheRatedTopAndKeepsItsOrderThere) {
  const auto fitted = [](std::optional<double> rated_top, std::string* description, double top_target = 4.2,
                         std::vector<double> group_tops = {4, 3.99, 2}) {
    residual::Augmentation a;
    a.kind = residual::EffectKind::kSensorCurve;
    a.channels = {"fc0"};
    auto& change = a.change.emplace<residual::CalibrationCurves>();
    change.curves = {{"fc0", {0, 1, 2, 3, 4}, {0, 1, 2, 3, 4}}};
    change.rated_top = rated_top;
    change.group_tops = group_tops;
    change.group_lowest = 0;
    const std::vector<double> target = {0, 2, 3, 3.9, top_target};  // readings at knots 0..4
    residual::TrainingRmse rmse;
    rmse.y_names = {"fc0", "l0"};
    rmse.all = [target](const SensorModel& s) {
      Eigen::VectorXd e = Eigen::VectorXd::Ones(2);
      if (const SensorCurve* c = s.curve_of("fc0"))
        for (std::size_t k = 1; k < target.size(); ++k) e(1) += std::pow(c->reading[k] - target[k], 2);
      return e;
    };
    std::vector<double> rates;
    change.refine(a, SensorModel{}, rmse, rates);
    if (description != nullptr) *description = a.description;
    return change.curves.front();
  };
  const SensorCurve free = fitted(std::nullopt, nullptr);
  ASSERT_EQ(free.level.size(), 5u);
  EXPECT_LT(free.reading[4], 4.5);  // follows the dip (4.2; the identity reads 4)
  std::string description;
  const SensorCurve anchored = fitted(8.0, &description);
  ASSERT_EQ(anchored.level, (std::vector<double>{0, 1, 2, 3, 4, 8}));
  EXPECT_EQ(anchored.reading.back(), 8.0);
  std::vector<double> slopes;
  for (std::size_t k = 1; k < anchored.level.size(); ++k)
    slopes.push_back((anchored.reading[k] - anchored.reading[k - 1]) / (anchored.level[k] - anchored.level[k - 1]));
  for (std::size_t k = 1; k < slopes.size(); ++k) EXPECT_LE(slopes[k], slopes[k - 1] + 1e-9) << k;
  for (double s : slopes) EXPECT_GE(s, 0.25);  // the search's bound (kMinSlope)
  // Above the dip: the top segment no steeper than the one below it.
  EXPECT_GT(anchored.reading[4], free.reading[4] + 0.3);
  EXPECT_NE(description.find("through the rated top 8"), std::string::npos) << description;
  // A rated top at or below the top knot is no anchor: the curve as without one.
  const SensorCurve below = fitted(4.0, nullptr);
  EXPECT_EQ(below.level, free.level);
  EXPECT_EQ(below.reading, free.reading);
  // A flat top where the group tops out together: the fit without the
  // rated top, ending at the slope bound.
  const SensorCurve flat = fitted(8.0, &description, 4.0);
  ASSERT_EQ(flat.level.size(), 5u);
  EXPECT_TRUE(residual::CalibrationCurves::flat_at_end(flat, +1));
  EXPECT_EQ(description.find("rated top"), std::string::npos) << description;
  // The same fit where one channel alone reaches the top: no rail, the rated top.
  const SensorCurve peak = fitted(8.0, &description, 4.0, {4, 3.7, 2});
  ASSERT_EQ(peak.level, (std::vector<double>{0, 1, 2, 3, 4, 8}));
  EXPECT_EQ(peak.reading.back(), 8.0);
  EXPECT_NE(description.find("through the rated top 8"), std::string::npos) << description;
}

// The curve refitted between parts of fine-tuning (CalibrationCurves::refit)
// starts from the slopes refine() fitted on the unchanged network and keeps
// its knots, its rated top and its shape. Two faked probes, each the squared
// distance of fc0's readings at knots 1..4 from a compressive target: the
// unchanged network's, which prefers the flatter readings 1.6, 2.6, 3.4, 4
// (slopes 1.6, 1, 0.8, 0.6: a curve learnt partly by the network), and
// the fine-tuned network's, which prefers the plant's 2, 3.4, 4.5, 5.4.
// The refit moves every reading from the first fit toward the second
// target; the curve ends at the rated top 8 as before, and the segment up
// to it keeps the order. The refit runs on every curve of the change, and
// the description says so.
TEST(SensorFrame, TheCurveIsRefittedFromItsSlopesOnTheFineTunedNetwork) {
  residual::Augmentation a;
  a.kind = residual::EffectKind::kSensorCurve;
  a.channels = {"fc0", "fc1"};
  auto& change = a.change.emplace<residual::CalibrationCurves>();
  change.curves = {{"fc0", {0, 1, 2, 3, 4}, {0, 1, 2, 3, 4}}, {"fc1", {0, 1, 2, 3, 4}, {0, 1, 2, 3, 4}}};
  change.rated_top = 8.0;
  change.group_tops = {4, 3, 2};
  const auto probe_least_at = [](std::vector<double> target) {  // readings at knots 1..4
    residual::TrainingRmse rmse;
    rmse.y_names = {"fc0", "l0"};
    rmse.all = [target](const SensorModel& s) {
      Eigen::VectorXd e = Eigen::VectorXd::Ones(2);
      if (const SensorCurve* c = s.curve_of("fc0"))
        for (std::size_t k = 1; k <= target.size(); ++k) e(1) += std::pow(c->reading[k] - target[k - 1], 2);
      return e;
    };
    return rmse;
  };
  const std::vector<double> unchanged = {1.6, 2.6, 3.4, 4.0}, tuned = {2.0, 3.4, 4.5, 5.4};
  std::vector<double> rates;
  change.refine(a, SensorModel{}, probe_least_at(unchanged), rates);
  ASSERT_TRUE(change.through_rated_top);
  const SensorCurve first = change.curves.front();
  ASSERT_EQ(first.level, (std::vector<double>{0, 1, 2, 3, 4, 8}));
  change.refit(a, SensorModel{}, probe_least_at(tuned), 10);
  ASSERT_EQ(change.curves.size(), 2u);
  const SensorCurve& refitted = change.curves.front();
  EXPECT_EQ(change.curves[1].reading, refitted.reading);  // one curve for the plan's channels
  ASSERT_EQ(refitted.level, first.level);
  EXPECT_EQ(refitted.reading.front(), 0.0);  // anchored at its lowest knot
  EXPECT_EQ(refitted.reading.back(), 8.0);   // through the rated top
  for (std::size_t k = 1; k <= 4; ++k) {
    // Closer to the tuned network's target than the first fit (which sat
    // within 0.3 of the unchanged network's: the targets differ by 0.4-1.4).
    EXPECT_LT(std::abs(refitted.reading[k] - tuned[k - 1]), std::abs(first.reading[k] - tuned[k - 1])) << k;
    EXPECT_GT(refitted.reading[k], first.reading[k]) << k;
  }
  std::vector<double> slopes;
  for (std::size_t k = 1; k < refitted.level.size(); ++k)
    slopes.push_back((refitted.reading[k] - refitted.reading[k - 1]) / (refitted.level[k] - refitted.level[k - 1]));
  for (std::size_t k = 1; k < slopes.size(); ++k) EXPECT_LE(slopes[k], slopes[k - 1] + 1e-9) << k;  // compressive
  EXPECT_NE(a.description.find("; refitted after 10 epochs of fine-tuning: 5 knots"), std::string::npos)
      << a.description;
}

// Channels top out together when at least two of them lie within 5 % of
// the span (from the group's lowest level to the highest top) from the
// highest; the span, not the level, so an offset changes nothing.
TEST(SensorFrame, ARailsChannelsTopOutTogether) {
  using residual::CalibrationCurves;
  EXPECT_TRUE(CalibrationCurves::tops_together({2.05, 2.04, 2.06, 0.05}, 0));
  EXPECT_TRUE(CalibrationCurves::tops_together({10, 9.5, 3}, 0));         // 0.5 of 10: at the edge
  EXPECT_FALSE(CalibrationCurves::tops_together({10, 9.4, 3}, 0));        // 0.6 of 10
  EXPECT_FALSE(CalibrationCurves::tops_together({16.2, 11.7, 11.2}, 0));  // a curve set's peaks (3884)
  EXPECT_TRUE(CalibrationCurves::tops_together({110, 109.5}, 100));       // 0.5 of a span of 10
  EXPECT_FALSE(CalibrationCurves::tops_together({110, 109}, 100));
  EXPECT_FALSE(CalibrationCurves::tops_together({2.05}, 0));              // one channel
  EXPECT_FALSE(CalibrationCurves::tops_together({}, 0));
}

// A channel of a curve's group takes a copy of the fitted curve only when
// it carries load on the training rows: at least min_rows of its levels
// more than 5 % of the fitted curve's span above its own lowest level.
// Stop 85's fresh curve set 4442: fc0 read 0 to 0.073 N in steps of
// 0.0122 N (12-bit over 50 N) beside a curve fitted from 0 to 18.66 N,
// and the copy raised its held-out error 1.51 times.
TEST(SensorFrame, AChannelAtRestTakesNoCopyOfTheCurve) {
  using residual::CalibrationCurves;
  std::vector<double> at_rest;
  for (int k = 0; k < 600; ++k) at_rest.push_back(0.0122 * (k % 7));
  std::sort(at_rest.begin(), at_rest.end());
  EXPECT_FALSE(CalibrationCurves::carries_load(at_rest, 18.66, 5));
  // A few rows of one grasp beyond the foot: 5 carry load, 4 do not.
  std::vector<double> grasped = at_rest;
  for (int k = 0; k < 4; ++k) grasped.push_back(1.0 + k);
  EXPECT_FALSE(CalibrationCurves::carries_load(grasped, 18.66, 5));
  grasped.push_back(5.0);
  EXPECT_TRUE(CalibrationCurves::carries_load(grasped, 18.66, 5));
  // The foot is the channel's own lowest level plus 5 % of the span (0.933
  // here): with a row needed, a level just below it is at rest, one just
  // beyond it carries load.
  std::vector<double> offset(600, 227.0);
  offset.push_back(227.0 + 0.05 * 18.66 - 1e-3);
  EXPECT_FALSE(CalibrationCurves::carries_load(offset, 18.66, 1));
  offset.back() += 2e-3;
  EXPECT_TRUE(CalibrationCurves::carries_load(offset, 18.66, 1));
  // At least one row, whatever min_rows says.
  EXPECT_FALSE(CalibrationCurves::carries_load(at_rest, 18.66, 0));
  EXPECT_FALSE(CalibrationCurves::carries_load({}, 18.66, 5));
}

// A drift re-estimated at rate 0 changes nothing, so it leaves the change,
// the affected channels and the channels the models are compared on
// (found_on).
// The plan of fresh drift set 2686 (600 rows, stop 67): the loadcells'
// drift at one rate for the group, and the screen's family member f4 (a
// tension), re-estimated at 0, which the change listed as drifting. A
// faked probe of the unchanged network: fc0's and fc1's errors are least
// at rate 0.02 (the grid of 2^(k/4) times 0.01 holds it), f4's grows with
// its rate.
TEST(SensorFrame, ADriftReEstimatedAtRateZeroLeavesTheChange) {
  residual::Augmentation a;
  a.kind = residual::EffectKind::kDriftLoad;
  a.channels = {"fc0", "f4", "fc1"};
  a.extended_channels = {"fc1"};
  a.found_on = {"fc0", "f4", "fc1"};
  auto& change = a.change.emplace<residual::BiasState>();
  change.drifts = {{"fc0", true, 0.01}, {"f4", true, 0.003}, {"fc1", true, 0.0}};
  change.period_s = 0.2;
  change.common_rate = true;
  residual::TrainingRmse rmse;
  rmse.y_names = {"fc0", "fc1", "f4"};
  rmse.all = [](const SensorModel& s) {
    Eigen::VectorXd e = Eigen::VectorXd::Ones(3);
    for (const SensorDrift& d : s.drifts) {
      if (d.channel == "f4") e(2) += d.rate;
      if (d.channel == "fc0") e(0) += std::pow(d.rate - 0.02, 2);
      if (d.channel == "fc1") e(1) += std::pow(d.rate - 0.02, 2);
    }
    return e;
  };
  std::vector<double> fitted;
  change.refine(a, SensorModel{}, rmse, fitted);
  ASSERT_EQ(change.drifts.size(), 2u);
  EXPECT_EQ(change.drifts[0].channel, "fc0");
  EXPECT_EQ(change.drifts[1].channel, "fc1");
  for (const SensorDrift& d : change.drifts) EXPECT_NEAR(d.rate, 0.02, 1e-12) << d.channel;
  EXPECT_EQ(a.channels, (std::vector<std::string>{"fc0", "fc1"}));
  EXPECT_EQ(a.extended_channels, (std::vector<std::string>{"fc1"}));
  EXPECT_EQ(a.found_on, (std::vector<std::string>{"fc0", "fc1"}));
  EXPECT_EQ(fitted, (std::vector<double>{0.01, 0.0}));  // the screen's rates of the drifts kept
  EXPECT_NE(a.description.find("left out at rate 0: f4"), std::string::npos) << a.description;

  // Every rate 0: the change stays as planned (it changes nothing and is never confirmed).
  residual::Augmentation none = a;
  auto& flat = std::get<residual::BiasState>(none.change);
  flat.drifts = {{"f4", true, 0.003}};
  flat.common_rate = false;
  none.channels = {"f4"};
  fitted.clear();
  flat.refine(none, SensorModel{}, rmse, fitted);
  ASSERT_EQ(flat.drifts.size(), 1u);
  EXPECT_EQ(flat.drifts[0].rate, 0.0);
  EXPECT_EQ(none.channels, (std::vector<std::string>{"f4"}));
}

// A cross-talk pair chains with a taken pair when its target is a taken
// target (two removals of one channel) or a taken source (its removal
// would change a source another removal subtracts as measured), or its
// source is a taken target (the sensor model would add back the corrected
// source, the removal subtracted the measured one).
TEST(Crosstalk, APairFormsAChainWithATakenPairsTargetOrSource) {
  const std::vector<SensorCrosstalk> taken = {{"fc1", "fc2", 0.3}};  // fc1 <- fc2
  EXPECT_TRUE(residual::forms_chain({"fc1", "fc3", 0.3}, taken));   // the same target
  EXPECT_TRUE(residual::forms_chain({"fc2", "fc3", 0.3}, taken));   // its target is the taken source
  EXPECT_TRUE(residual::forms_chain({"fc0", "fc1", 0.3}, taken));   // its source is the taken target
  EXPECT_FALSE(residual::forms_chain({"fc0", "fc2", 0.3}, taken));  // a shared source: no chain
  EXPECT_FALSE(residual::forms_chain({"fc3", "fc4", 0.3}, taken));  // disjoint
  EXPECT_FALSE(residual::forms_chain({"fc3", "fc4", 0.3}, {}));
}

// A curve's end as flat as its fit may be: one more step of the search
// (x 0.93) would cross the slope bound 1/4 (CalibrationCurves::flat_at_end,
// the simpler account's rail signature).
TEST(SensorFrame, ACurvesEndIsFlatWhereItsFitCouldGoNoFlatter) {
  using residual::CalibrationCurves;
  // Slopes 0.26 on [0, 1], 1 on [1, 2], 0.26 on [2, 3]: 0.26 x 0.93 < 1/4.
  const SensorCurve flat{"fc0", {0, 1, 2, 3}, {0, 0.26, 1.26, 1.52}};
  EXPECT_TRUE(CalibrationCurves::flat_at_end(flat, 1));
  EXPECT_TRUE(CalibrationCurves::flat_at_end(flat, -1));
  // Slope 0.27 at both ends: 0.27 x 0.93 = 0.2511, a step the search could still take.
  const SensorCurve steeper{"fc0", {0, 1, 2, 3}, {0, 0.27, 1.27, 1.54}};
  EXPECT_FALSE(CalibrationCurves::flat_at_end(steeper, 1));
  EXPECT_FALSE(CalibrationCurves::flat_at_end(steeper, -1));
  // One end flat, the other not: the side decides.
  const SensorCurve top_only{"fc0", {0, 1, 2}, {0, 1, 1.25}};
  EXPECT_TRUE(CalibrationCurves::flat_at_end(top_only, 1));
  EXPECT_FALSE(CalibrationCurves::flat_at_end(top_only, -1));
}

TEST(FixCandidates, TheFirstSignificantElseTheClearestGainElseNoneIsTested) {
  auto trial = [](double stat, bool judged = true) {
    residual::CandidateTrial c;
    c.selection.mean = stat / 100;  // the sign of the statistic
    c.selection.stat = stat;
    c.selection.p_value = 0.5 * std::erfc(stat / std::sqrt(2.0));  // one-sided normal
    c.selected_by_training_rows = judged;
    return c;
  };
  const auto chosen = [](const std::vector<residual::CandidateTrial>& c) { return residual::chosen_candidate(c, 0.01); };
  // The first significant at 0.01 (statistic 2.6, p 0.0047) before a clearer later one.
  EXPECT_EQ(chosen({trial(-1.0), trial(2.6), trial(3.5)}), 1u);
  // None significant: the clearest gain, wherever it is.
  EXPECT_EQ(chosen({trial(1.2), trial(2.0), trial(-3.0)}), 1u);
  EXPECT_EQ(chosen({trial(-1.0), trial(0.4)}), 1u);
  // Nothing gains: none is tested (the training rows support none).
  EXPECT_EQ(chosen({trial(-1.0), trial(-4.0)}), std::nullopt);
  EXPECT_EQ(chosen({trial(0), trial(0)}), std::nullopt);
  // Candidates that were not judged (logs too short for the selection, or
  // after the first significant one) are not chosen; none judged: the
  // screen's first.
  EXPECT_EQ(chosen({trial(0.0, false), trial(5.0, false)}), 0u);
  EXPECT_EQ(chosen({trial(1.0), trial(2.6), trial(9.0, false)}), 1u);
  EXPECT_EQ(chosen({trial(-1.0), trial(9.0, false)}), std::nullopt);
  EXPECT_EQ(chosen({}), 0u);
}

// --fix-selection every-channel (best_candidate): every candidate is judged
// on every channel, so the statistics compare alike: the largest among the
// significant ones, wherever it is in the screen's order; else the largest
// positive; none when nothing gains.
TEST(FixCandidates, EveryChannelTakesTheLargestSignificantStatistic) {
  auto trial = [](double stat, bool judged = true) {
    residual::CandidateTrial c;
    c.selection.mean = stat / 100;
    c.selection.stat = stat;
    c.selection.p_value = 0.5 * std::erfc(stat / std::sqrt(2.0));
    c.selected_by_training_rows = judged;
    return c;
  };
  const auto best = [](const std::vector<residual::CandidateTrial>& c) { return residual::best_candidate(c, 0.01); };
  // Both significant at 0.01 (p 0.0047 and 0.0002): the larger, not the first.
  EXPECT_EQ(best({trial(-1.0), trial(2.6), trial(3.5)}), 2u);
  EXPECT_EQ(best({trial(3.5), trial(2.6)}), 0u);
  // None significant: the largest positive.
  EXPECT_EQ(best({trial(1.2), trial(2.0), trial(-3.0)}), 1u);
  EXPECT_EQ(best({trial(-1.0), trial(-4.0)}), std::nullopt);
  // Not judged: never chosen; none judged: the screen's first.
  EXPECT_EQ(best({trial(1.0), trial(9.0, false)}), 0u);
  EXPECT_EQ(best({trial(0.0, false), trial(5.0, false)}), 0u);
  EXPECT_STREQ(residual::selection_rule_name(residual::SelectionRule::kEveryChannel), "every-channel");
  EXPECT_EQ(residual::selection_rule_named("screen-order"), residual::SelectionRule::kScreenOrder);
  EXPECT_FALSE(residual::selection_rule_named("best").has_value());
}

// The plans fix() tries as the simpler account of a confirmed calibration
// curve (EffectInfo::simpler: a rail): the rails planned on the curve's
// lead channel, fewest channels first, else those on another channel the
// curve was found on (since stop 82: one curve for its channels, so its
// lead is one of them); none for a rail only on a channel the curve was
// not found on, for a plan that cannot be added, or for an effect without
// a simpler one. (With none planned, the ranking without the floor is
// searched: here it is empty; cli.residual.rail_simpler_account runs it.)
TEST(FixCandidates, TheSimplerAccountIsARailWhereTheCurveWasFound) {
  const auto plan = [](residual::EffectKind kind, std::vector<std::string> channels, bool group_extension = true) {
    residual::Augmentation a;
    a.kind = kind;
    a.channels = std::move(channels);
    a.group_extension = group_extension;
    return a;
  };
  using residual::EffectKind;
  residual::ResidualData data;
  data.y_names = {"fc0", "fc1", "fc2", "fc3", "fc4", "fc5", "fc6", "fc7", "fc8"};
  const residual::Attribution floorless;
  const auto simpler = [&](const std::vector<residual::Augmentation>& planned) {
    std::vector<std::vector<std::string>> out;
    for (const auto& a : residual::simpler_plans(data, floorless, planned, 0)) out.push_back(a.channels);
    return out;
  };
  using Channels = std::vector<std::vector<std::string>>;
  // Found on fc4, fc3 and fc0, and applied to the rest of the group (fc7, ...).
  residual::Augmentation curve = plan(EffectKind::kSensorCurve, {"fc4", "fc3", "fc0", "fc7"});
  curve.found_on = {"fc4", "fc3", "fc0"};
  std::vector<residual::Augmentation> planned = {curve, plan(EffectKind::kSaturation, {"fc4", "fc3", "fc7"}),
                                                 plan(EffectKind::kSaturation, {"fc4"}, false)};
  EXPECT_EQ(simpler(planned), (Channels{{"fc4"}, {"fc4", "fc3", "fc7"}}));
  planned.pop_back();  // the extended rail alone
  EXPECT_EQ(simpler(planned), (Channels{{"fc4", "fc3", "fc7"}}));
  // The rails of the lead before those of the other channels it was found on.
  planned = {curve, plan(EffectKind::kSaturation, {"fc3"}), plan(EffectKind::kSaturation, {"fc4"})};
  EXPECT_EQ(simpler(planned), (Channels{{"fc4"}}));
  // None of the lead: a rail of fc3, where the curve was found too (stop
  // 81's code asked the lead only and found none).
  planned = {curve, plan(EffectKind::kSaturation, {"fc3"})};
  EXPECT_EQ(simpler(planned), (Channels{{"fc3"}}));
  // A rail of fc7 only, where the curve was applied and not found, is no account of it.
  planned = {curve, plan(EffectKind::kSaturation, {"fc7"})};
  EXPECT_EQ(simpler(planned), Channels{});
  // A rail plan that cannot be added.
  planned = {curve, plan(EffectKind::kSaturation, {"fc4"})};
  planned[1].not_fixable = "nothing to clip";
  EXPECT_EQ(simpler(planned), Channels{});
  // A rail has no simpler account; neither has a delay.
  planned = {plan(EffectKind::kSaturation, {"fc4"}), plan(EffectKind::kSensorCurve, {"fc4"})};
  EXPECT_EQ(simpler(planned), Channels{});
  planned = {plan(EffectKind::kSensorDelay, {"fc4"}), plan(EffectKind::kSaturation, {"fc4"})};
  EXPECT_EQ(simpler(planned), Channels{});
}

// A plan of `kind` on `channels`, as plan_candidates() gives it; the rules
// tested with it read only kind, channels and not_fixable.
residual::Augmentation planned_on(residual::EffectKind kind, std::vector<std::string> channels) {
  residual::Augmentation a;
  a.kind = kind;
  a.channels = std::move(channels);
  return a;
}

// The simpler account of a confirmed friction (EffectInfo::simpler: a
// calibration curve, a static map where friction adds a state): the curves
// planned on its lead channel, fewest channels first; none for a curve of
// its group that leaves the lead channel out.
TEST(FixCandidates, TheSimplerAccountOfFrictionIsACurveOnItsLeadChannel) {
  const auto plan = planned_on;
  using residual::EffectKind;
  residual::ResidualData data;
  data.y_names = {"fc0", "fc1", "fc2", "fc3", "fc4", "fc5", "fc6", "fc7", "fc8"};
  const residual::Attribution floorless;
  const residual::Augmentation friction = plan(EffectKind::kFriction, {"fc4"});
  const auto simpler = [&](const std::vector<residual::Augmentation>& planned) {
    std::vector<std::vector<std::string>> out;
    for (const auto& a : residual::simpler_plans(data, floorless, planned, 0)) out.push_back(a.channels);
    return out;
  };
  using Channels = std::vector<std::vector<std::string>>;
  EXPECT_EQ(simpler({friction, plan(EffectKind::kSensorCurve, {"fc3", "fc2", "fc4", "fc7", "fc0"}),
                     plan(EffectKind::kSensorCurve, {"fc3", "fc2", "fc4"})}),
            (Channels{{"fc3", "fc2", "fc4"}, {"fc3", "fc2", "fc4", "fc7", "fc0"}}));
  EXPECT_EQ(simpler({friction, plan(EffectKind::kSensorCurve, {"fc6", "fc1", "fc7"})}), Channels{});
  // A rail of the lead is no account of friction.
  EXPECT_EQ(simpler({friction, plan(EffectKind::kSaturation, {"fc4"})}), Channels{});
}

// The plans fix() tries as the richer account of a confirmed cross-talk
// (EffectInfo::richer: a calibration curve, when every pair the removal
// takes reads a channel of its target's group): the curves planned on its
// lead channel (the winner's target), fewest channels first; none for a
// removal with a pair between groups (a tension leaking into a loadcell is
// no loadcell's curve), for a curve that leaves the target out, and none
// for a curve, which names no richer effect.
TEST(FixCandidates, TheRicherAccountOfACrosstalkWithinAGroupIsItsGroupsCurve) {
  using residual::EffectKind;
  const auto plan = [](EffectKind kind, std::vector<std::string> channels) {
    residual::Augmentation a;
    a.kind = kind;
    a.channels = std::move(channels);
    return a;
  };
  const auto crosstalk = [&](std::vector<SensorCrosstalk> pairs) {
    residual::Augmentation a = plan(EffectKind::kCrosstalk, {});
    for (const auto& p : pairs) a.channels.push_back(p.target);
    a.change = residual::CrosstalkRemoval{{}, std::move(pairs)};
    return a;
  };
  residual::ResidualData data;
  data.y_names = {"f5", "fc0", "fc1", "fc2", "fc3", "fc4", "fc6", "fc7"};
  const residual::Attribution floorless;
  const auto richer = [&](const std::vector<residual::Augmentation>& planned) {
    std::vector<std::vector<std::string>> out;
    for (const auto& a : residual::richer_plans(data, floorless, planned, 0)) out.push_back(a.channels);
    return out;
  };
  using Channels = std::vector<std::vector<std::string>>;
  const auto group_curve = plan(EffectKind::kSensorCurve, {"fc1", "fc3", "fc7", "fc4", "fc2"});
  const auto family_curve = plan(EffectKind::kSensorCurve, {"fc1", "fc3"});
  const auto within = crosstalk({{"fc1", "fc2", 0.43}});
  EXPECT_EQ(richer({within, group_curve, family_curve}), (Channels{{"fc1", "fc3"}, group_curve.channels}));
  EXPECT_EQ(richer({crosstalk({{"fc1", "fc2", 0.43}, {"fc3", "fc4", 0.3}}), group_curve}), Channels{group_curve.channels});
  // A pair between groups anywhere in the removal: no curve stands for it.
  EXPECT_EQ(richer({crosstalk({{"fc6", "f5", 0.2}}), plan(EffectKind::kSensorCurve, {"fc6", "fc1"})}), Channels{});
  EXPECT_EQ(richer({crosstalk({{"fc1", "fc2", 0.43}, {"fc6", "f5", 0.2}}), group_curve}), Channels{});
  // A curve without the target.
  EXPECT_EQ(richer({within, plan(EffectKind::kSensorCurve, {"fc3", "fc4"})}), Channels{});
  // A curve names no richer account; a cross-talk has no simpler one.
  EXPECT_EQ(richer({group_curve, within}), Channels{});
  EXPECT_TRUE(residual::simpler_plans(data, floorless, {within, group_curve}, 0).empty());
}

// With no rail among the candidates, the simpler account is planned from
// the ranking without its floor: on the lead's group and side only, the
// lead first, though a rail of another group (a length's lower rail) or
// side ranks above it.
TEST(FixCandidates, ASimplerAccountBelowTheFloorKeepsTheLeadsGroupAndSide) {
  residual::ResidualData data;
  data.y_names = {"l4", "fc3", "fc4", "fc7"};
  residual::Attribution floorless;
  const auto rail = [&](int target, int side, double level) {
    residual::HypothesisResult r;
    r.hypothesis = {residual::EffectKind::kSaturation, target, -1, 0, side, level};
    r.effect = "saturation";
    r.label = "rail of " + data.y_names[static_cast<std::size_t>(target)];
    r.p_adjusted = 1e-9;
    r.explained = 0.3;
    r.significant = true;
    return r;
  };
  // In ranking order: l4's lower rail, fc7's lower rail, fc4's and fc3's upper rails.
  floorless.ranked = {rail(0, -1, 224.9), rail(3, -1, 0.1), rail(2, +1, 3.04), rail(1, +1, 3.05)};
  residual::Augmentation curve;
  curve.kind = residual::EffectKind::kSensorCurve;
  curve.channels = {"fc3", "fc7"};
  const auto plans = residual::simpler_plans(data, floorless, {curve}, 0);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].channels, (std::vector<std::string>{"fc3", "fc4"}));
  EXPECT_EQ(plans[0].kind, residual::EffectKind::kSaturation);
  // No significant rail on the lead: nothing.
  floorless.ranked.pop_back();
  EXPECT_TRUE(residual::simpler_plans(data, floorless, {curve}, 0).empty());
}

// The ranking fix() plans its candidates from (candidates_view): by
// default (stop 48) down to an excess share of 1, below the screen's 3;
// never above the screen's floor; unset, the screen's; without a null the
// absolute floors. Three drift hypotheses, significant but for the floor,
// with shares 5, 2 and 0.5.
// The plans the next round of --rounds also tries
// (earlier_candidates_for_next_round): a round's plans it did not apply, in
// order, but none of an effect confirmed in any round (the chosen one's
// included: a confirmed curve replaced by its simpler rail keeps no other
// curve), none that cannot be added, and none that is the confirmed
// change's other account of the same residual (friction's simpler curve
// on a channel friction was found on; a curve elsewhere stays).
TEST(FixCandidates, TheNextRoundTriesWhatThisRoundDidNotApply) {
  using residual::EffectKind;
  const auto plan = [](EffectKind kind, const std::string& effect, std::vector<std::string> channels) {
    residual::Augmentation a;
    a.kind = kind;
    a.effect = effect;
    a.channels = std::move(channels);
    a.found_on = a.channels;
    return a;
  };
  residual::FixResult fixed;
  fixed.candidate_plans = {plan(EffectKind::kFriction, "friction", {"f1", "f0", "f2"}),
                           plan(EffectKind::kSensorCurve, "sensor-curve", {"f0", "f5"}),
                           plan(EffectKind::kSensorDelay, "sensor-delay", {"fc3", "fc4", "fc1"}),
                           plan(EffectKind::kSensorDelay, "sensor-delay", {"fc3"}),
                           plan(EffectKind::kSensorCurve, "sensor-curve", {"fc3", "fc4"}),
                           plan(EffectKind::kFriction, "friction", {"f1"}),
                           plan(EffectKind::kSaturation, "saturation", {"fc2"})};
  fixed.candidate_plans.back().not_fixable = "nothing to clip";
  fixed.candidates.resize(fixed.candidate_plans.size());
  for (std::size_t k = 0; k < fixed.candidates.size(); ++k)
    fixed.candidates[k].effect = fixed.candidate_plans[k].effect;
  fixed.candidates[0].chosen = true;
  fixed.augmentation = fixed.candidate_plans[0];
  const auto next = [&](const std::vector<std::string>& confirmed) {
    std::vector<std::vector<std::string>> out;
    for (const auto& a : residual::earlier_candidates_for_next_round(fixed, confirmed)) out.push_back(a.channels);
    return out;
  };
  using Channels = std::vector<std::vector<std::string>>;
  EXPECT_EQ(next({"friction"}), (Channels{{"fc3", "fc4", "fc1"}, {"fc3"}, {"fc3", "fc4"}}));
  // An earlier round confirmed a sensor delay: no delay again.
  EXPECT_EQ(next({"sensor-delay", "friction"}), (Channels{{"fc3", "fc4"}}));
  // The chosen candidate was a curve and its simpler rail was applied: no curve
  // is carried; the rail's other account (a curve) is on fc2 only.
  fixed.candidates[0].chosen = false;
  fixed.candidates[4].chosen = true;
  fixed.augmentation = plan(EffectKind::kSaturation, "saturation", {"fc3"});
  EXPECT_EQ(next({"saturation"}), (Channels{{"f1", "f0", "f2"}, {"fc3", "fc4", "fc1"}, {"fc3"}, {"f1"}}));
  // Nothing confirmed has nothing to carry beyond what was not chosen.
  fixed.augmentation.reset();
  fixed.candidates[4].chosen = false;
  EXPECT_EQ(next({}).size(), 6u);
}

// A sensor delay's steps come from its group (effects.cc, group_delay):
// each channel votes for the steps whose delay explains most of its
// held-out residual, and more than half of the voters for other steps than
// the lead's move the plan there. Modelled on fresh logs with loadcells 2
// steps late, where a 1-step delay of fc0 led the ranking.
TEST(FixCandidates, ASensorDelaysStepsAreThoseMostOfItsGroupShow) {
  residual::ResidualData data;
  data.y_names = {"fc0", "fc1", "fc2", "fc3", "fc4"};
  residual::Attribution screen;
  // (target, steps, held-out explained share, gain, significant); every one passes Holm's test.
  const auto add = [&](int target, int steps, double explained, double gain, bool significant) {
    residual::HypothesisResult r;
    r.hypothesis = {residual::EffectKind::kSensorDelay, target, -1, steps, 0, 0};
    r.effect = "sensor-delay";
    r.label = "delay = " + std::to_string(steps) + " on " + data.y_names[static_cast<std::size_t>(target)];
    r.parameter = gain;
    r.explained = explained;
    r.p_adjusted = 1e-20;
    r.significant = significant;
    screen.ranked.push_back(r);
  };
  add(0, 1, 0.39, 0.57, true);   // the lead: fc0 nearly at rest on the null
  add(3, 2, 0.77, 0.82, true);
  add(4, 2, 0.67, 0.82, true);
  add(3, 1, 0.38, 0.90, true);
  add(0, 2, 0.41, 0.48, false);  // below the gain bound, still a vote for 2 steps
  add(1, 2, 0.31, 0.69, false);
  add(1, 1, 0.30, 0.68, false);
  add(2, 1, 0.20, 0.30, false);
  const auto first_plan = [&] {
    const std::vector<residual::Augmentation> plans = residual::plan_candidates(data, screen, 1);
    EXPECT_EQ(plans.size(), 1u);
    return plans.empty() ? residual::Augmentation{} : plans.front();
  };
  const auto steps_of = [](const residual::Augmentation& a) {
    const auto* alignment = std::get_if<residual::TimeAlignment>(&a.change);
    return alignment != nullptr ? alignment->delay : -1;
  };
  // fc0, fc1, fc3 and fc4 (4 of 5) are best explained by 2 steps: fc3's delay leads.
  residual::Augmentation a = first_plan();
  EXPECT_EQ(steps_of(a), 2);
  EXPECT_EQ(a.channels, (std::vector<std::string>{"fc3", "fc4", "fc0", "fc1"}));
  EXPECT_NE(a.description.find("the group's delay: 2 steps explain most of 4 of fc's 5 channels"), std::string::npos)
      << a.description;
  // The most voters, but not more than half of them: the lead's 1 step stays.
  screen.ranked[4].explained = 0.35;  // fc0 now votes for 1 step (0.39)
  add(1, 3, 0.50, 0.60, false);       // fc1 for 3 steps
  add(2, 4, 0.25, 0.40, false);       // fc2 for 4 steps: 2 steps have 2 of 5 voters
  a = first_plan();
  EXPECT_EQ(steps_of(a), 1);
  EXPECT_EQ(a.description.find("the group's delay"), std::string::npos) << a.description;
  // A majority for steps that no significant delay has leaves the lead too.
  screen.ranked.resize(8);
  screen.ranked[4].explained = 0.41;
  for (std::size_t k : {1u, 2u}) screen.ranked[k].significant = false;
  a = first_plan();
  EXPECT_EQ(steps_of(a), 1);
}

TEST(FixCandidates, ByDefaultTheyReachDownToAShareOfOne) {
  residual::Attribution screen;
  screen.null = residual::NullCalibration{};
  const double shares[3] = {5.0, 2.0, 0.5};
  for (int target = 0; target < 3; ++target) {
    residual::HypothesisResult r;
    r.hypothesis.kind = residual::EffectKind::kDriftLoad;
    r.hypothesis.target = target;
    r.label = "drift on y" + std::to_string(target);
    r.p_adjusted = 1e-6;
    r.explained = 0.5;
    r.excess_share = shares[target];
    screen.ranked.push_back(r);
  }
  screen = residual::with_null_floor(screen, residual::kDefaultMinExcessNull);  // the screen at its floor of 3
  const auto significant = [](const residual::Attribution& a) {
    std::vector<int> targets;
    for (const auto& r : a.ranked)
      if (r.significant) targets.push_back(r.hypothesis.target);
    return targets;
  };
  ASSERT_EQ(significant(screen), std::vector<int>({0}));
  residual::FixOptions options;
  EXPECT_EQ(significant(residual::candidates_view(screen, options)), std::vector<int>({0, 1}));
  options.min_excess_null.reset();
  EXPECT_EQ(significant(residual::candidates_view(screen, options)), std::vector<int>({0}));
  options.min_excess_null = 10.0;  // above the screen's: the screen's
  EXPECT_EQ(significant(residual::candidates_view(screen, options)), std::vector<int>({0}));
  options.min_excess_null = 0.1;
  EXPECT_EQ(significant(residual::candidates_view(screen, options)), std::vector<int>({0, 1, 2}));
  // A screen already below the default keeps its own floor.
  const residual::Attribution low = residual::with_null_floor(screen, 0.4);
  EXPECT_EQ(significant(residual::candidates_view(low, residual::FixOptions{})), std::vector<int>({0, 1, 2}));
  // Without a null the screen's ranking stays (its absolute floors).
  residual::Attribution absolute = screen;
  absolute.null.reset();
  EXPECT_EQ(significant(residual::candidates_view(absolute, residual::FixOptions{})), significant(absolute));
}

// A calibration curve's plan is one curve for its group's channels, so the
// candidates take a curve at its group's summed excess share: the sum over
// the group's significant curves (augment.cc, planning_order); and a curve
// is a candidate once per group. Modelled on stop 86's curve set 4448,
// where the loadcells' curves (each diluted by the rows at rest) ranked
// below a cross-talk and a tendon's curve, which took the curve's one place.
TEST(FixCandidates, ACurveStandsAtItsGroupsSummedExcessShare) {
  residual::ResidualData data;
  data.y_names = {"f4", "fc3", "fc4", "fc5"};
  data.y_scale = Eigen::VectorXd::Ones(4);
  residual::ResidualLog log;
  log.seq.y = Eigen::MatrixXd::Zero(4, 40);
  for (int t = 0; t < 40; ++t) log.seq.y.col(t) << 10.0 + t, 0.1 * t, 0.2 * t, 0.05 * t;  // every channel loaded
  data.logs.push_back(std::move(log));
  residual::Attribution screen;
  screen.null = residual::NullCalibration{};
  // (kind, target, source, excess share); every one passes Holm's test and the explained share's floor.
  const auto add = [&](residual::EffectKind kind, int target, int source, double excess) {
    residual::HypothesisResult r;
    r.hypothesis = {kind, target, source, 0, 0, 0};
    r.effect = residual::effect_info(kind).name;
    r.label = r.effect + " on " + data.y_names[static_cast<std::size_t>(target)];
    r.testable = true;
    r.plausible = true;
    r.parameter = 0.3;
    r.p_adjusted = 1e-10;
    r.explained = 0.3;
    r.excess_share = excess;
    screen.ranked.push_back(r);
  };
  add(residual::EffectKind::kCrosstalk, 2, 1, 4.0);  // fc3 -> fc4
  add(residual::EffectKind::kSensorCurve, 0, -1, 3.0);  // the tendon's curve, one channel
  add(residual::EffectKind::kSensorCurve, 1, -1, 2.5);  // the loadcells': 2.5 + 2.0 = 4.5 over the group
  add(residual::EffectKind::kSensorCurve, 2, -1, 2.0);
  screen = residual::with_null_floor(screen, 1.0);
  const auto plans = residual::plan_candidates(data, screen, 2);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[0].kind, residual::EffectKind::kSensorCurve) << plans[0].description;
  EXPECT_EQ(plans[0].found_on, (std::vector<std::string>{"fc3", "fc4"})) << plans[0].description;
  EXPECT_EQ(plans[1].kind, residual::EffectKind::kCrosstalk) << plans[1].description;
  // The screen's statistic each plan shows stays its lead's own.
  EXPECT_DOUBLE_EQ(plans[0].screen_statistic, 2.5);
  // The winner (the cross-talk) can be added: the curve planned before it
  // says nothing of it.
  EXPECT_EQ(plans[0].description.find("is not added"), std::string::npos) << plans[0].description;
  // Only significant curves count: with fc3's failing Holm's test at the
  // same share, the loadcells' 2.0 (not 4.5) stay below the tendon's 3.0,
  // which then takes the curve's place.
  ASSERT_EQ(screen.ranked[2].hypothesis.target, 1);
  screen.ranked[2].p_adjusted = 0.5;
  screen = residual::with_null_floor(screen, 1.0);
  const auto below = residual::plan_candidates(data, screen, 2);
  ASSERT_EQ(below.size(), 2u);
  EXPECT_EQ(below[0].kind, residual::EffectKind::kCrosstalk) << below[0].description;
  EXPECT_EQ(below[1].found_on, std::vector<std::string>{"f4"}) << below[1].description;
  // A curve is a candidate once per group: the loadcells' comes third.
  const auto three = residual::plan_candidates(data, screen, 3);
  ASSERT_EQ(three.size(), 3u);
  EXPECT_EQ(three[2].found_on, std::vector<std::string>{"fc4"}) << three[2].description;
}

// The drift probe (drift_probe.h) as pure code, its rows faked: the grid's
// start in closed form, one probe per channel group that the sensor model
// does not already drift, Holm's correction over the groups, and which group
// becomes the candidate. A group's loss with its drift is its loss without
// less a fixed gain plus a wobble (the Diebold-Mariano test needs
// variance); tolerance 1e-12 on the closed forms.
TEST(DriftProbe, OneLoadDriftPerGroupAtOneRateTheBestGroupACandidate) {
  residual::ResidualData data;
  data.y_names = {"a0", "a1", "b0", "c0"};
  data.y_scale = Eigen::VectorXd(4);
  data.y_scale << 1.0, 3.0, 2.0, 1.0;
  for (int k = 0; k < 2; ++k) {
    residual::ResidualLog log;
    log.dt_s = 0.5;
    log.seq.y = Eigen::MatrixXd::Zero(4, 3);
    log.seq.y.row(0) << 1, -2, 3;      // sum |y| = 6
    log.seq.y.row(1) << 2, 2, 2 + k;   // 6, 7
    log.seq.y.row(2) << 0.5, 0.5, 0;   // 1
    data.logs.push_back(std::move(log));
  }
  // a: load dt averaged over a0, a1 and the two logs, (6 + 6 + 6 + 7) / 4 * 0.5;
  // the std averaged over a0, a1, 2: a quarter of it over that load.
  EXPECT_NEAR(residual::start_rate(data, {"a0", "a1"}), 0.25 * 2.0 / (25.0 / 4 * 0.5), 1e-12);
  EXPECT_NEAR(residual::start_rate(data, {"b0"}), 0.25 * 2.0 / 0.5, 1e-12);
  EXPECT_EQ(residual::start_rate(data, {"c0"}), 0.0);  // no level: not probed
  EXPECT_THROW(residual::start_rate(data, {"z0"}), std::logic_error);

  const residual::Augmentation plan = residual::group_drift_plan({"a0", "a1"}, 0.5, 0.01);
  EXPECT_EQ(plan.kind, residual::EffectKind::kDriftLoad);
  EXPECT_EQ(plan.found_on, (std::vector<std::string>{"a0", "a1"}));
  const auto& bias = std::get<residual::BiasState>(plan.change);
  EXPECT_TRUE(bias.common_rate);
  EXPECT_EQ(bias.period_s, 0.5);
  EXPECT_EQ(bias.drifts, (std::vector<SensorDrift>{{"a0", true, 0.01}, {"a1", true, 0.01}}));

  HadynetModel model;
  model.layout.y_names = data.y_names;
  // The fake rows: group a's rate re-estimated at twice its start, b's at
  // zero; the loss with a drift lowered by `gain` per row.
  std::map<std::string, double> gain{{"a0", 0.5}, {"b0", 0.5}};
  residual::DriftProbeRows rows;
  rows.refined = [](residual::Augmentation a) {
    for (auto& d : std::get<residual::BiasState>(a.change).drifts) d.rate = d.channel[0] == 'a' ? 2 * d.rate : 0.0;
    return a;
  };
  rows.loss = [&](const SensorModel& sensor, const std::vector<std::string>& channels) {
    Eigen::VectorXd loss(60);
    for (int i = 0; i < 60; ++i)
      loss(i) = 4.0 + std::sin(0.7 * i) - (sensor.drifts.empty() ? 0.0 : gain[channels.front()] + std::cos(1.3 * i));
    return residual::Segments{loss};
  };
  std::vector<residual::DriftProbe> probes = residual::probe_drifts(model, data, rows, 0.01);
  ASSERT_EQ(probes.size(), 3u);  // a, b and c, in the order they first appear
  EXPECT_EQ(probes[0].group, "a");
  EXPECT_EQ(probes[0].channels, (std::vector<std::string>{"a0", "a1"}));
  EXPECT_NEAR(probes[0].rate, 2 * probes[0].start_rate, 1e-12);
  EXPECT_GT(probes[0].gain.mean, 0.4);
  EXPECT_TRUE(probes[0].candidate);
  EXPECT_LE(probes[0].gain.p_value, probes[0].p_adjusted);
  // Holm over the groups tested: b's rate is 0 and c carries no level, so a alone.
  EXPECT_NEAR(probes[0].p_adjusted, probes[0].gain.p_value, 1e-12);
  EXPECT_EQ(probes[1].rate, 0.0);  // no drift at its best rate: no test, no candidate
  EXPECT_EQ(probes[1].p_adjusted, 1.0);
  EXPECT_FALSE(probes[1].candidate);
  // Two groups tested: Holm doubles the smaller p (b's gain made larger than a's).
  rows.refined = [](residual::Augmentation a) {
    for (auto& d : std::get<residual::BiasState>(a.change).drifts) d.rate *= 2;
    return a;
  };
  gain["b0"] = 0.8;
  const std::vector<residual::DriftProbe> both = residual::probe_drifts(model, data, rows, 0.01);
  ASSERT_EQ(both.size(), 3u);
  const double p_a = both[0].gain.p_value, p_b = both[1].gain.p_value;
  ASSERT_LT(p_b, p_a);
  EXPECT_NEAR(both[1].p_adjusted, std::min(1.0, 2 * p_b), 1e-12);
  EXPECT_NEAR(both[0].p_adjusted, std::min(1.0, std::max(2 * p_b, p_a)), 1e-12);
  // Both candidates are proposed, the smaller adjusted p first (stop 71).
  ASSERT_TRUE(both[0].candidate && both[1].candidate);
  const std::vector<const residual::DriftProbe*> proposed = residual::candidate_drift_probes(both);
  ASSERT_EQ(proposed.size(), 2u);
  EXPECT_EQ(proposed[0]->group, "b");
  EXPECT_EQ(proposed[1]->group, "a");
  rows.refined = [](residual::Augmentation a) {
    for (auto& d : std::get<residual::BiasState>(a.change).drifts) d.rate = d.channel[0] == 'a' ? 2 * d.rate : 0.0;
    return a;
  };
  gain["b0"] = 0.5;
  EXPECT_EQ(probes[2].start_rate, 0.0);
  EXPECT_FALSE(probes[2].candidate);
  ASSERT_EQ(residual::candidate_drift_probes(probes).size(), 1u);
  EXPECT_EQ(residual::candidate_drift_probes(probes).front()->group, "a");
  // A loss that rises with the drift is no candidate.
  gain["a0"] = -0.5;
  EXPECT_TRUE(residual::candidate_drift_probes(residual::probe_drifts(model, data, rows, 0.01)).empty());
  // A channel the sensor model already drifts is left out of its group; a
  // group it drifts whole is not probed.
  gain["a0"] = 0.5;
  model.sensor.drifts = {{"a0", true, 0.02}, {"b0", true, 0.02}};
  probes = residual::probe_drifts(model, data, rows, 0.01);
  ASSERT_EQ(probes.size(), 2u);
  EXPECT_EQ(probes[0].channels, (std::vector<std::string>{"a1"}));
  EXPECT_EQ(probes[1].group, "c");
  // Logs of different periods: nothing probed (a drift needs one period).
  data.logs[1].dt_s = 0.25;
  EXPECT_TRUE(residual::probe_drifts(model, data, rows, 0.01).empty());
}

TEST(DriftProbe, ItsCandidateFollowsTheScreensDriftOfItsGroupElseComesLast) {
  // Plans as plan_candidates() gives them; only kind, channels and
  // not_fixable matter to the place.
  const auto plan = [](residual::EffectKind kind, const std::string& channel) {
    residual::Augmentation a;
    a.kind = kind;
    a.channels = {channel};
    return a;
  };
  using residual::EffectKind;
  const auto curve = plan(EffectKind::kSensorCurve, "fc1");
  const auto fc_drift = plan(EffectKind::kDriftLoad, "fc0");
  const auto f_drift = plan(EffectKind::kDriftLoad, "f4");
  const auto crosstalk = plan(EffectKind::kCrosstalk, "fc1");
  const auto place = [](const std::vector<residual::Augmentation>& planned, const std::string& group) {
    const residual::ProbePlace p = residual::drift_probe_place(planned, group);
    return std::make_pair(p.at, p.replaces_all);
  };
  // A place left (2 of 3, --candidates 3): last.
  EXPECT_EQ(place({curve, crosstalk}, "fc"), std::make_pair(std::size_t{2}, false));
  // Every place taken and no load drift (drift sets 2986, 2995 and 3161):
  // last, beyond the count. Before stop 72 the probe did not run there.
  EXPECT_EQ(place({curve, crosstalk, curve}, "fc"), std::make_pair(std::size_t{3}, false));
  // The screen's drift of the group: right after it, beyond the count.
  EXPECT_EQ(place({curve, fc_drift, crosstalk}, "fc"), std::make_pair(std::size_t{2}, false));
  // A drift of another group only, every place taken (drift set 2461 of
  // stop 64: a tendon's drift, curves and cross-talks): last, beyond the
  // count. Before stop 65 it had no place there.
  EXPECT_EQ(place({f_drift, curve, crosstalk}, "fc"), std::make_pair(std::size_t{3}, false));
  EXPECT_EQ(place({f_drift, curve, crosstalk}, "f"), std::make_pair(std::size_t{1}, false));
  // A drift family led by a tendon's tension that holds a loadcell (drift
  // set 2762 of stop 68: f4 and fc4) is a drift of both groups: the
  // loadcells' probe follows it. Until stop 68 it came last, beyond the
  // count, and a curve gained first on the selection's rows.
  auto mixed_drift = f_drift;
  mixed_drift.channels = {"f4", "fc4"};
  EXPECT_EQ(place({mixed_drift, curve, crosstalk}, "fc"), std::make_pair(std::size_t{1}, false));
  EXPECT_EQ(place({mixed_drift, curve, crosstalk}, "f"), std::make_pair(std::size_t{1}, false));
  EXPECT_EQ(place({mixed_drift, curve, crosstalk}, "l"), std::make_pair(std::size_t{3}, false));
  // A second candidate group (stop 71: every candidate group is proposed)
  // always has a place once the first is in: last, beyond the count.
  const auto fc_probe = plan(EffectKind::kDriftLoad, "fc2");
  EXPECT_EQ(place({curve, crosstalk, fc_probe}, "th"), std::make_pair(std::size_t{3}, false));
  EXPECT_EQ(place({curve, fc_drift, fc_probe, crosstalk}, "f"), std::make_pair(std::size_t{4}, false));
  // Nothing that can be added: the only one.
  auto unfixable = curve;
  unfixable.not_fixable = "no knots";
  EXPECT_EQ(place({unfixable}, "fc"), std::make_pair(std::size_t{0}, true));
  EXPECT_EQ(place({}, "fc"), std::make_pair(std::size_t{0}, true));
  // A drift that cannot be added counts as none: last.
  auto unfixable_drift = f_drift;
  unfixable_drift.not_fixable = "no level";
  EXPECT_EQ(place({curve, unfixable_drift, crosstalk}, "f"), std::make_pair(std::size_t{3}, false));
}

// Which choice of the selection gives way to the drift probe's plan of its
// group (stop 69: on drift sets 2763 and 2768 the screen's drift of one to
// three loadcells was chosen and not confirmed, where the plant's drift of
// every loadcell passes). Only kind, channels and not_fixable matter.
TEST(DriftProbe, ALoadDriftOfItsGroupGivesWayToItsPlanAndNothingElseDoes) {
  const auto plan = planned_on;
  using residual::EffectKind;
  const auto probe = plan(EffectKind::kDriftLoad, {"fc0", "fc1", "fc2", "fc3"});
  const auto family = plan(EffectKind::kDriftLoad, {"fc3", "fc1"});
  const auto tendon_led = plan(EffectKind::kDriftLoad, {"f4", "fc4"});  // 2762's family: holds a loadcell
  const auto tendon = plan(EffectKind::kDriftLoad, {"f4"});
  const auto time_drift = plan(EffectKind::kDriftTime, {"fc3"});
  const auto curve = plan(EffectKind::kSensorCurve, {"fc3"});
  const std::vector<residual::Augmentation> planned = {curve, family, tendon_led, tendon, time_drift, probe};
  const std::size_t probed = planned.size() - 1;
  EXPECT_TRUE(residual::gives_way_to_group_drift(planned, 1, probed));
  EXPECT_TRUE(residual::gives_way_to_group_drift(planned, 2, probed));
  // Another group's drift, another kind of drift, another effect: no.
  EXPECT_FALSE(residual::gives_way_to_group_drift(planned, 3, probed));
  EXPECT_FALSE(residual::gives_way_to_group_drift(planned, 4, probed));
  EXPECT_FALSE(residual::gives_way_to_group_drift(planned, 0, probed));
  // The probe's own plan, or an index out of range: no.
  EXPECT_FALSE(residual::gives_way_to_group_drift(planned, probed, probed));
  EXPECT_FALSE(residual::gives_way_to_group_drift(planned, 1, planned.size()));
  // A drift that cannot be added is no choice to give way.
  auto unfixable = planned;
  unfixable[1].not_fixable = "no level";
  EXPECT_FALSE(residual::gives_way_to_group_drift(unfixable, 1, probed));
}

// A curve's rivals are the other effects of its group, a time drift's the
// load drifts of its group, a load drift's the curves and time drifts of
// its groups; another effect has none in its groups. Every choice's rivals
// also hold every plan of the groups it does not hold (stop 88).
TEST(DecisionRivals, ACurveAndATimeDriftHaveRivalsInTheirGroupAndALoadDriftIsEachsRival) {
  const auto plan = planned_on;
  using residual::EffectKind;
  using Rivals = std::vector<std::size_t>;
  const auto curve = plan(EffectKind::kSensorCurve, {"fc3", "fc1"});
  const auto family = plan(EffectKind::kDriftLoad, {"fc1"});
  const auto tendon_led = plan(EffectKind::kDriftLoad, {"f4", "fc4"});  // holds a loadcell
  const auto tendon = plan(EffectKind::kDriftLoad, {"f4"});
  const auto time_drift = plan(EffectKind::kDriftTime, {"fc3"});
  const auto crosstalk = plan(EffectKind::kCrosstalk, {"fc3"});
  const auto tendon_curve = plan(EffectKind::kSensorCurve, {"f2"});
  const std::vector<residual::Augmentation> planned = {curve,      family,    tendon_led,  tendon,
                                                       time_drift, crosstalk, tendon_curve};
  // A curve's: the other effects of its group, and every plan of the
  // groups it does not hold (the tendon's drift 3 and curve 6).
  EXPECT_EQ(residual::decision_rivals(planned, 0), (Rivals{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 1), (Rivals{0, 3, 4, 6}));
  // A drift of a tendon and a loadcell: the curves and time drifts of
  // either group (it holds every plan's group).
  EXPECT_EQ(residual::decision_rivals(planned, 2), (Rivals{0, 4, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 3), (Rivals{0, 1, 4, 5, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 4), (Rivals{1, 2, 3, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 6), (Rivals{0, 1, 2, 3, 4, 5}));
  // Another effect: none of its group, the plans of the other groups.
  EXPECT_EQ(residual::decision_rivals(planned, 5), (Rivals{3, 6}));
  // An index out of range: none.
  EXPECT_TRUE(residual::decision_rivals(planned, planned.size()).empty());
  // A plan that cannot be added is no rival, and has none.
  auto unfixable = planned;
  unfixable[1].not_fixable = "no level";
  EXPECT_EQ(residual::decision_rivals(unfixable, 0), (Rivals{2, 3, 4, 5, 6}));
  EXPECT_TRUE(residual::decision_rivals(unfixable, 1).empty());
  // The drift probe's plans (indices 2 and 3 here) are a drift's rivals
  // (a load drift's or a drift with time's) whatever their group, and of
  // nothing else beyond the rules above.
  const Rivals probed = {2, 3};
  EXPECT_EQ(residual::decision_rivals(planned, 1, probed), (Rivals{0, 2, 3, 4, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 2, probed), (Rivals{0, 3, 4, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 3, probed), (Rivals{0, 1, 2, 4, 5, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 0, probed), (Rivals{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 4, probed), (Rivals{1, 2, 3, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 6, probed), (Rivals{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(residual::decision_rivals(planned, 5, probed), (Rivals{3, 6}));
  EXPECT_EQ(residual::decision_rivals(unfixable, 3, probed), (Rivals{0, 2, 4, 5, 6}));
  unfixable[2].not_fixable = "no level";
  EXPECT_EQ(residual::decision_rivals(unfixable, 3, probed), (Rivals{0, 4, 5, 6}));
}

// A cross-talk within a group stands in for the group's calibration curve
// (its richer account): its rivals in its group are the group's curves and
// load drifts. A cross-talk between groups (a tension leaking into a
// loadcell) has none in its group. Either has the plans of the groups it
// does not hold (stop 88), the drift probe's too.
TEST(DecisionRivals, ACrosstalkWithinAGroupHasItsGroupsCurvesAndLoadDriftsAsRivals) {
  const auto plan = planned_on;
  using residual::EffectKind;
  using Rivals = std::vector<std::size_t>;
  const auto removal = [&](std::vector<SensorCrosstalk> pairs) {
    auto a = plan(EffectKind::kCrosstalk, {pairs.front().target});
    residual::CrosstalkRemoval change;
    change.pairs = std::move(pairs);
    a.change = change;
    return a;
  };
  const auto within = removal({{"fc1", "fc2", 0.3}, {"fc3", "fc4", 0.2}});
  const auto between = removal({{"fc6", "f5", 0.1}});
  const auto mixed = removal({{"fc1", "fc2", 0.3}, {"fc6", "f5", 0.1}});
  const std::vector<residual::Augmentation> planned = {
      within,
      plan(EffectKind::kSensorCurve, {"fc1", "fc4"}),
      plan(EffectKind::kDriftLoad, {"fc0", "fc1"}),
      plan(EffectKind::kDriftTime, {"fc1"}),
      plan(EffectKind::kFriction, {"fc1"}),
      plan(EffectKind::kSensorCurve, {"f2"}),
      plan(EffectKind::kDriftLoad, {"th0"}),
      between,
      mixed,
  };
  EXPECT_EQ(residual::decision_rivals(planned, 0), (Rivals{1, 2, 5, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 0, {6}), (Rivals{1, 2, 5, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 7), (Rivals{5, 6}));
  EXPECT_EQ(residual::decision_rivals(planned, 8), (Rivals{5, 6}));
  // A friction's rivals are the curves of its group (stop 74), and the
  // plans of the other groups.
  EXPECT_EQ(residual::decision_rivals(planned, 4), (Rivals{1, 5, 6}));
  // A curve's rivals hold the cross-talks of its group, as before, and the
  // plans of the other groups (5, 6).
  EXPECT_EQ(residual::decision_rivals(planned, 1), (Rivals{0, 2, 3, 4, 5, 6, 7, 8}));
}

// Friction has the calibration curves of its groups as rivals (stop 74:
// on curve logs friction of a tendon's command on its loadcell was chosen
// where the curves' gain on the selection's rows was larger but noisier),
// and nothing else of its groups: not a drift or a cross-talk; beyond
// them every plan (stop 88).
TEST(DecisionRivals, AFrictionHasTheCurvesOfItsGroupsAsRivals) {
  const auto plan = planned_on;
  using residual::EffectKind;
  using Rivals = std::vector<std::size_t>;
  const std::vector<residual::Augmentation> planned = {
      plan(EffectKind::kFriction, {"fc4"}),
      plan(EffectKind::kSensorCurve, {"fc1", "fc3"}),
      plan(EffectKind::kSensorCurve, {"f2"}),
      plan(EffectKind::kDriftLoad, {"fc4"}),
      plan(EffectKind::kCrosstalk, {"fc4"}),
      plan(EffectKind::kSensorCurve, {"fc4"}),
      plan(EffectKind::kFriction, {"f0", "th0"}),
      plan(EffectKind::kSensorCurve, {"th1"}),
  };
  EXPECT_EQ(residual::decision_rivals(planned, 0), (Rivals{1, 2, 5, 6, 7}));
  // Of each group it holds, and every plan of the loadcells.
  EXPECT_EQ(residual::decision_rivals(planned, 6), (Rivals{0, 1, 2, 3, 4, 5, 7}));
  // In its groups, a drift probe's plan is a rival of a drift only.
  EXPECT_EQ(residual::decision_rivals(planned, 0, {3}), (Rivals{1, 2, 5, 6, 7}));
  // A curve that cannot be added is no rival.
  auto unfixable = planned;
  unfixable[5].not_fixable = "no level";
  EXPECT_EQ(residual::decision_rivals(unfixable, 0), (Rivals{1, 2, 6, 7}));
  // A curve's rivals hold the frictions of its group, as before, and the
  // plans of the groups it does not hold (f2, the tendon's friction, th1).
  EXPECT_EQ(residual::decision_rivals(planned, 5), (Rivals{0, 2, 3, 4, 6, 7}));
}

// A rail's rivals are the plans of the groups it does not hold (stop 75:
// a lower rail of the finger lengths chosen on curve logs, the curves of
// other groups; since stop 88 every plan there, as for every choice), and
// they must have gained more than the rail on the selection's rows; a
// rival that holds one of the choice's groups need only have gained.
TEST(DecisionRivals, ARailHasThePlansOfOtherGroupsAsRivalsThatGainedMoreThanIt) {
  const auto plan = planned_on;
  using residual::EffectKind;
  using Rivals = std::vector<std::size_t>;
  const std::vector<residual::Augmentation> planned = {
      plan(EffectKind::kSaturation, {"l3", "l4"}),
      plan(EffectKind::kSensorCurve, {"fc1", "fc3"}),
      plan(EffectKind::kSensorCurve, {"l3"}),
      plan(EffectKind::kCrosstalk, {"fc1"}),
      plan(EffectKind::kSensorCurve, {"f2", "fc0"}),
      plan(EffectKind::kSaturation, {"fc3"}),
      plan(EffectKind::kDriftLoad, {"fc1"}),
  };
  // Every plan of the other groups; not the lengths' own curve.
  EXPECT_EQ(residual::decision_rivals(planned, 0), (Rivals{1, 3, 4, 5, 6}));
  // The loadcells' rail has no rival in its group, and the curve of f2 and
  // fc0 holds one of its channels' group (fc).
  EXPECT_EQ(residual::decision_rivals(planned, 5), (Rivals{0, 2}));
  auto unfixable = planned;
  unfixable[1].not_fixable = "no level";
  EXPECT_EQ(residual::decision_rivals(unfixable, 0), (Rivals{3, 4, 5, 6}));
  // A curve's rivals still hold the rails of its group, and the plans of
  // the groups it does not hold.
  EXPECT_EQ(residual::decision_rivals(planned, 2), (Rivals{0, 1, 3, 4, 5, 6}));
  // The gain a rival of the groups the choice does not hold must exceed:
  // the choice's own, never below 0 (a choice that lost on the selection's
  // rows), whatever the two effects.
  EXPECT_DOUBLE_EQ(residual::rival_gain_floor(planned[0], planned[1], 0.0045, false), 0.0045);
  EXPECT_DOUBLE_EQ(residual::rival_gain_floor(planned[0], planned[1], -0.2, false), 0.0);
  EXPECT_DOUBLE_EQ(residual::rival_gain_floor(planned[1], planned[0], 0.12, false), 0.12);
  EXPECT_DOUBLE_EQ(residual::rival_gain_floor(planned[2], planned[1], 0.0001, false), 0.0001);
  EXPECT_DOUBLE_EQ(residual::rival_gain_floor(planned[2], planned[1], -0.01, false), 0.0);
  EXPECT_DOUBLE_EQ(residual::rival_gain_floor(planned[6], planned[0], 0.3, false), 0.3);
  // A rival that holds one of the choice's groups need only have gained.
  EXPECT_DOUBLE_EQ(residual::rival_gain_floor(planned[2], planned[0], 0.0001, false), 0.0);
  EXPECT_DOUBLE_EQ(residual::rival_gain_floor(planned[6], planned[1], 0.3, false), 0.0);
  // So need the drift probe's plans of a drift, of any group; of another
  // choice they are plans like any other.
  EXPECT_DOUBLE_EQ(residual::rival_gain_floor(planned[6], planned[0], 0.3, true), 0.0);
  EXPECT_DOUBLE_EQ(residual::rival_gain_floor(planned[1], planned[0], 0.12, true), 0.12);
}

// --fix-tie-break fewest-channels (fewest_channels_among_ties): of the
// plan with the largest gain and the confirmed plans that tie with it, the
// one changing the fewest channels; the larger gain among equally few; a
// plan that does not tie is never taken, however few its channels. Exact:
// indices.
TEST(DecisionRivals, OfTiedPlansTheOneChangingTheFewestChannelsIsApplied) {
  using residual::TestedPlan;
  using residual::fewest_channels_among_ties;
  // [0] the choice (1 channel, gain 0), [1] a curve of nine channels with
  // the largest gain: the choice ties with it and is applied.
  EXPECT_EQ(fewest_channels_among_ties({{1, 0.0, true}, {9, 0.003, false}}, 1), 0u);
  // The choice does not tie (the largest gain beats it significantly): the
  // largest gain's plan is applied.
  EXPECT_EQ(fewest_channels_among_ties({{1, 0.0, false}, {9, 0.14, false}}, 1), 1u);
  // The largest gain's plan changes the fewest itself: it is applied.
  EXPECT_EQ(fewest_channels_among_ties({{8, 0.0, true}, {4, 0.02, false}}, 1), 1u);
  // The choice has the largest gain; a rival of 4 channels ties: applied.
  EXPECT_EQ(fewest_channels_among_ties({{8, 0.0, false}, {4, -0.026, true}}, 0), 1u);
  // Two tied rivals of 4 channels each: the larger gain; a tied plan of
  // 6 and an untied plan of 2 are not taken.
  EXPECT_EQ(fewest_channels_among_ties({{9, 0.0, true}, {4, 0.01, true}, {4, 0.05, true}, {6, 0.2, false},
                                        {2, 0.0, false}, {6, 0.1, true}},
                                       3),
            2u);
  // A tie of channels and gain with the largest's plan: that plan.
  EXPECT_EQ(fewest_channels_among_ties({{3, 0.0, true}, {3, 0.0, false}}, 1), 1u);
  // One plan alone.
  EXPECT_EQ(fewest_channels_among_ties({{5, 0.0, false}}, 0), 0u);
}

// A model of two y channels, a and b, of standard deviations 2 and 4.
HadynetModel loss_model() {
  HadynetModel m;
  m.layout.y_names = {"a", "b"};
  m.norm.y.mean = Eigen::VectorXd::Zero(2);
  m.norm.y.std.resize(2);
  m.norm.y.std << 2.0, 4.0;
  return m;
}

// The per-row loss of --fix's Diebold-Mariano tests (standardised_loss):
// each channel's error over the model's standard deviation of it, squared
// or absolute (--decision-loss), averaged over the channels asked for, one
// segment per log. Exact: hand-computed values, tolerance 1e-12.
TEST(DecisionLoss, TheMeanOverTheChannelsOfTheStandardisedErrorSquaredOrAbsolute) {
  const HadynetModel m = loss_model();
  residual::HeldOutError e;
  e.channels = {"b", "a"};  // the evaluation's order need not be the model's
  e.residuals.resize(2);
  e.residuals[0] = {Eigen::Vector2d(4.0, -8.0), Eigen::Vector3d(0.0, 2.0, -4.0)};  // b: two logs
  e.residuals[1] = {Eigen::Vector2d(-2.0, 1.0), Eigen::Vector3d(4.0, 0.0, 2.0)};   // a
  using residual::DecisionLoss;
  const residual::Segments sq = residual::standardised_loss(m, e, {"a", "b"}, DecisionLoss::kSquared);
  const residual::Segments ab = residual::standardised_loss(m, e, {"a", "b"}, DecisionLoss::kAbsolute);
  ASSERT_EQ(sq.size(), 2u);
  ASSERT_EQ(ab.size(), 2u);
  // Log 0, row 0: a -2/2 = -1, b 4/4 = 1; row 1: a 0.5, b -2.
  EXPECT_NEAR(sq[0](0), (1.0 + 1.0) / 2, 1e-12);
  EXPECT_NEAR(sq[0](1), (0.25 + 4.0) / 2, 1e-12);
  EXPECT_NEAR(ab[0](0), (1.0 + 1.0) / 2, 1e-12);
  EXPECT_NEAR(ab[0](1), (0.5 + 2.0) / 2, 1e-12);
  // Log 1: a 2, 0, 1; b 0, 0.5, -1.
  const Eigen::Vector3d sq1(4.0 / 2, 0.25 / 2, 2.0 / 2), ab1(2.0 / 2, 0.5 / 2, 2.0 / 2);
  EXPECT_LT((sq[1] - sq1).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((ab[1] - ab1).cwiseAbs().maxCoeff(), 1e-12);
  // One channel alone is that channel's loss.
  EXPECT_NEAR(residual::standardised_loss(m, e, {"b"}, DecisionLoss::kAbsolute)[0](1), 2.0, 1e-12);
  EXPECT_THROW(residual::standardised_loss(m, e, {"c"}, DecisionLoss::kSquared), std::logic_error);
  EXPECT_STREQ(residual::decision_loss_name(DecisionLoss::kSquared), "squared");
  EXPECT_STREQ(residual::decision_loss_name(DecisionLoss::kAbsolute), "absolute");
  EXPECT_EQ(residual::decision_loss_named("absolute"), DecisionLoss::kAbsolute);
  EXPECT_EQ(residual::decision_loss_named("squared"), DecisionLoss::kSquared);
  EXPECT_FALSE(residual::decision_loss_named("Squared").has_value());
}

// --decision-scale residual: each channel's standardised error is also
// divided by the square root of its clean residual level on the null
// (residual_levels), so that each channel's relative change counts alike.
// Exact: hand-computed values, tolerance 1e-12.
TEST(DecisionLoss, InResidualUnitsEachChannelIsDividedByItsCleanLevel) {
  const HadynetModel m = loss_model();
  residual::HeldOutError e;
  e.channels = {"a", "b"};
  e.residuals.resize(2);
  e.residuals[0] = {Eigen::Vector2d(-2.0, 1.0)};  // a: standardised -1, 0.5
  e.residuals[1] = {Eigen::Vector2d(4.0, -8.0)};  // b: 1, -2
  // The null's levels (mean squared standardised residual): a 0.25, b 4.
  Eigen::VectorXd level(2);
  level << 0.25, 4.0;
  const residual::ResidualLevels levels = residual::residual_levels(m.layout.y_names, level);
  ASSERT_EQ(levels.size(), 2u);
  using residual::DecisionLoss;
  const residual::Segments sq = residual::standardised_loss(m, e, {"a", "b"}, DecisionLoss::kSquared, &levels);
  const residual::Segments ab = residual::standardised_loss(m, e, {"a", "b"}, DecisionLoss::kAbsolute, &levels);
  // Row 0: a -1/0.5 = -2, b 1/2 = 0.5; row 1: a 1, b -1.
  EXPECT_NEAR(sq[0](0), (4.0 + 0.25) / 2, 1e-12);
  EXPECT_NEAR(sq[0](1), (1.0 + 1.0) / 2, 1e-12);
  EXPECT_NEAR(ab[0](0), (2.0 + 0.5) / 2, 1e-12);
  EXPECT_NEAR(ab[0](1), (1.0 + 1.0) / 2, 1e-12);
  // Without levels, the standard-deviation units: row 0 (1 + 1) / 2.
  EXPECT_NEAR(residual::standardised_loss(m, e, {"a", "b"}, DecisionLoss::kSquared)[0](0), 1.0, 1e-12);
  // A channel the levels lack is an error, not a silent unit.
  const residual::ResidualLevels only_a{{"a", 0.25}};
  EXPECT_THROW(residual::standardised_loss(m, e, {"b"}, DecisionLoss::kSquared, &only_a), std::logic_error);
  // A level that is not positive takes the smallest positive one; none positive: no levels.
  level << 0.0, 4.0;
  EXPECT_DOUBLE_EQ(residual::residual_levels(m.layout.y_names, level).at("a"), 4.0);
  EXPECT_TRUE(residual::residual_levels(m.layout.y_names, Eigen::VectorXd::Zero(2)).empty());
  EXPECT_STREQ(residual::decision_scale_name(residual::DecisionScale::kStd), "std");
  EXPECT_STREQ(residual::decision_scale_name(residual::DecisionScale::kResidual), "residual");
  EXPECT_EQ(residual::decision_scale_named("residual"), residual::DecisionScale::kResidual);
  EXPECT_FALSE(residual::decision_scale_named("relative").has_value());
}

// The rows fix() fine-tunes on and judges (decision_rows): the first fold and
// the selection as before stop 47, and the mirrored fold only where its
// judged rows end before the selection's (no row judged twice, none that
// chose the candidate judged again) and no model is judged on a row it was
// fine-tuned on. A model fine-tuned on raw rows [a, b) whose frame is
// aligned by a delay of s <= d reads raw rows up to b - 1 and, through the
// alignment, predicts nothing the judged rows hold. Exact integers.
TEST(DecisionRows, TheFoldsNeverJudgeARowTwiceNorOneTheyTrainedOn) {
  using Span = residual::DecisionRows::Span;
  const auto eq = [](Span a, int from, int to) { return a.from == from && a.to == to; };
  // The benchmarks' logs: 300 rows, train_fraction 0.6 (split 180), no delay and a 2-step one.
  const residual::DecisionRows r0 = residual::decision_rows(300, 180, 0);
  EXPECT_TRUE(eq(r0.train, 0, 180) && eq(r0.held_out, 180, 300));
  EXPECT_TRUE(eq(r0.selection_train, 0, 135) && eq(r0.selection_judged, 135, 180));
  EXPECT_TRUE(eq(r0.mirrored_train, 120, 300) && eq(r0.mirrored_judged, 2, 120));
  EXPECT_TRUE(r0.can_select && r0.mirrored);
  const residual::DecisionRows r2 = residual::decision_rows(300, 180, 2);
  EXPECT_TRUE(eq(r2.held_out, 180, 298) && eq(r2.selection_judged, 135, 178) && eq(r2.mirrored_judged, 4, 120));
  EXPECT_TRUE(r2.mirrored);
  // train_fraction 0.4: the mirrored judged rows would reach [120, 180), the
  // first fold's training rows, and the selection's judged rows [90, 120).
  EXPECT_FALSE(residual::decision_rows(300, 120, 0).mirrored);
  // Just at 4/7 (split 172, inner 129, T - split 128) and just below (171: inner 128, T - split 129).
  EXPECT_TRUE(residual::decision_rows(300, 172, 0).mirrored);
  EXPECT_FALSE(residual::decision_rows(300, 171, 0).mirrored);
  // Too short for 20 mirrored rows.
  EXPECT_FALSE(residual::decision_rows(50, 30, 0).mirrored);
  // Every log length, split and delay: wherever the mirrored fold is judged,
  // its judged rows are disjoint from every other judged span and from its
  // own training rows, and non-empty.
  const auto disjoint = [](Span a, Span b) { return a.to <= b.from || b.to <= a.from; };
  for (int T = 40; T <= 400; T += 7)
    for (int d = 0; d <= 5; ++d)
      for (int split = d + 2; split < T - d; split += 3) {
        const residual::DecisionRows r = residual::decision_rows(T, split, d);
        ASSERT_TRUE(eq(r.train, 0, split) && eq(r.held_out, split, T - d));
        if (!r.mirrored) continue;
        ASSERT_GE(r.mirrored_judged.to - r.mirrored_judged.from, residual::DecisionRows::kMinSelectionRows);
        ASSERT_TRUE(disjoint(r.mirrored_judged, r.held_out)) << T << " " << split << " " << d;
        ASSERT_TRUE(disjoint(r.mirrored_judged, r.selection_judged)) << T << " " << split << " " << d;
        ASSERT_TRUE(disjoint(r.mirrored_judged, r.mirrored_train)) << T << " " << split << " " << d;
        ASSERT_GE(r.mirrored_judged.from, d + 2);
        ASSERT_EQ(r.mirrored_train.to, T);
      }
}

}  // namespace
}  // namespace hadynet::test
