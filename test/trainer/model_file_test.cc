// The HADYNET model file (trainer/model_file.h): an exact round trip of
// every part of a model, and every kind of malformed file rejected with a
// ModelFileError that starts with the path and names the problem.
// Round-trip comparisons are exact (bits): the file stores float tensors as
// F32 and the normalisation/detection statistics as F64.
#include "trainer/model_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "synthetic_logs.h"
#include "test_batches.h"
#include "trainer/detection.h"
#include "trainer/hadynet_network.h"
#include "trainer/training.h"

namespace hadynet::trainer::testing {
namespace {

namespace st = safetensors;

// A consistent model with generic values everywhere (no tensor constant),
// two PB states, and optionally detection statistics.
HadynetModel sample_model(bool with_detection) {
  const FeatureLayout layout = spring_layout();
  const std::vector<LogSequence> seqs = {spring_sequence(1.0, 30, 1, "soft"),
                                         spring_sequence(6.0, 30, 2, "stiff")};
  HadynetModel m = new_model(layout, fit_normalization(seqs, layout),
                             {{"soft", "ball"}, {"stiff", ""}}, /*pb_dim=*/2, /*hidden=*/8,
                             /*train_steps=*/5, /*seed=*/3);
  m.params = generic_params(m.params.dims, 5).cast<float>();
  m.bn_batches_tracked = 42;
  m.hyper_parameters = {{"lr", "0.01"}, {"batch", "25"}};
  m.provenance = {{"data_hash", "0123456789abcdef"}, {"logs", "a.csv\nb.csv"}};
  if (with_detection) {
    // The robot profile goes with this variant; the other one has none.
    m.profile.force_groups = {"q"};
    m.profile.control_commands = {"u0"};
    m.profile.board_group = "q";
    m.period_s = 0.05;  // the other variant records none (0), as files from before periods
    m.profile.contact_sums = {{"all", {"q0", "q1"}}};
    std::mt19937_64 rng(17);
    DetectionCalibration c;
    c.steps = 3;
    c.pb = random_matrix(rng, 2, 1);
    c.mean = random_matrix(rng, 4, 1, 0.1);
    const Eigen::MatrixXd a = random_matrix(rng, 4, 4);
    c.covariance = a * a.transpose() + 0.5 * Eigen::MatrixXd::Identity(4, 4);
    c.inverse = regularised_inverse(c.covariance);
    c.threshold = 4.25;
    c.samples = 123;
    c.source = "calib/none.csv";
    m.detection = c;
    // Ranges go with the detection variant; the other one is a model
    // without them (as files written before they existed).
    ValueRanges r;
    double v = 0.125;
    for (const ValueRangeField& field : kValueRangeFields) r.*field.member = (v *= 1.7);
    r.windows = 321;
    r.source = "spring logs \"a\" (data_hash 0123)";
    m.ranges = r;
    // And a sensor model (hadynet residual --fix) with every part.
    const auto& y = m.layout.y_names;
    m.sensor.delays = {{y.front(), 2}, {y.back(), 1}};
    m.sensor.crosstalk = {{y.front(), y.back(), 0.25}};
    m.sensor.drifts = {{y.back(), true, 0.004}, {y.front(), false, -0.5}};
    m.sensor.period_s = 0.2;
    m.sensor.curves = {{y.front(), {0.0, 0.5, 2.0}, {0.0, 0.75, 2.25}}};
    m.sensor.clips = {{y.front(), 1, 0.1875}, {y.back(), -1, -2.5}};
    // And held-out logs (stored as texts; the loader does not parse them).
    m.held_out_logs = {{"a.csv rows 18..19", "# format: hadynet-log\nt,q0\n0,1\n"}, {"b.csv rows 9..12", "x"}};
  }
  return m;
}

WindowBatch<float> float_batch(const HadynetDims& dims, int B, int N) {
  const WindowBatch<double> b = random_batch(dims, B, N, 77, {0, 1});
  WindowBatch<float> f;
  f.x0 = b.x0.cast<float>();
  f.u = b.u.cast<float>();
  f.state = b.state;
  return f;
}

void expect_same_model(const HadynetModel& got, const HadynetModel& want) {
  EXPECT_TRUE(bit_identical(got.params, want.params));
  EXPECT_EQ(got.layout, want.layout);
  EXPECT_EQ(got.norm.x.mean, want.norm.x.mean);
  EXPECT_EQ(got.norm.x.std, want.norm.x.std);
  EXPECT_EQ(got.norm.u.mean, want.norm.u.mean);
  EXPECT_EQ(got.norm.u.std, want.norm.u.std);
  EXPECT_EQ(got.norm.y.mean, want.norm.y.mean);
  EXPECT_EQ(got.norm.y.std, want.norm.y.std);
  ASSERT_EQ(got.states.size(), want.states.size());
  for (std::size_t k = 0; k < got.states.size(); ++k) {
    EXPECT_EQ(got.states[k].name, want.states[k].name);
    EXPECT_EQ(got.states[k].object, want.states[k].object);
  }
  EXPECT_EQ(got.train_steps, want.train_steps);
  EXPECT_EQ(got.period_s, want.period_s);
  EXPECT_EQ(got.bn_batches_tracked, want.bn_batches_tracked);
  EXPECT_EQ(got.hyper_parameters, want.hyper_parameters);
  EXPECT_EQ(got.provenance, want.provenance);
  EXPECT_EQ(got.profile, want.profile);
  ASSERT_EQ(got.detection.has_value(), want.detection.has_value());
  if (want.detection) {
    const DetectionCalibration& g = *got.detection;
    const DetectionCalibration& w = *want.detection;
    EXPECT_EQ(g.steps, w.steps);
    EXPECT_EQ(g.pb, w.pb);
    EXPECT_EQ(g.mean, w.mean);
    EXPECT_EQ(g.covariance, w.covariance);
    EXPECT_EQ(g.inverse, w.inverse);
    EXPECT_EQ(g.threshold, w.threshold);
    EXPECT_EQ(g.samples, w.samples);
    EXPECT_EQ(g.source, w.source);
  }
  EXPECT_TRUE(got.sensor == want.sensor);
  EXPECT_EQ(got.held_out_logs, want.held_out_logs);
  ASSERT_EQ(got.ranges.has_value(), want.ranges.has_value());
  if (want.ranges) {
    EXPECT_EQ(*got.ranges, *want.ranges);  // doubles exactly (JSON round trip)
  }
}

TEST(ModelFile, RoundTripKeepsEveryPartAndTheForwardBits) {
  TempDir dir;
  const HadynetModel model = sample_model(true);
  const std::string path = (dir.path() / "m.safetensors").string();
  save_model(path, model);
  const HadynetModel loaded = load_model(path);
  expect_same_model(loaded, model);
  EXPECT_EQ(loaded.state_index("stiff"), 1);
  EXPECT_EQ(loaded.state_index("nope"), -1);
  EXPECT_EQ(loaded.period_s, 0.05);

  // Same bits in, same bits out: the forward pass (BN eval) is bit-identical.
  const WindowBatch<float> batch = float_batch(model.params.dims, 6, 5);
  HadynetNetwork<float> a, b;
  const Matrix<float> ya = a.forward(model.params, batch, BnMode::kEval);
  const Matrix<float> yb = b.forward(loaded.params, batch, BnMode::kEval);
  ASSERT_EQ(ya.size(), yb.size());
  EXPECT_EQ(std::memcmp(ya.data(), yb.data(), sizeof(float) * static_cast<std::size_t>(ya.size())), 0);

  // Saving the loaded model gives the same bytes (the writer is deterministic).
  const std::string again = (dir.path() / "again.safetensors").string();
  save_model(again, loaded);
  EXPECT_EQ(st::serialize(st::read_file(again)), st::serialize(st::read_file(path)));
}

TEST(ModelFile, RoundTripWithoutDetection) {
  TempDir dir;
  const HadynetModel model = sample_model(false);
  const std::string path = (dir.path() / "m.safetensors").string();
  save_model(path, model);
  const HadynetModel loaded = load_model(path);
  EXPECT_FALSE(loaded.detection.has_value());
  EXPECT_FALSE(loaded.ranges.has_value());
  EXPECT_EQ(model_to_safetensors(loaded).metadata.count("ranges"), 0u);
  EXPECT_EQ(loaded.period_s, 0.0) << "a file without 'period_s' has none recorded";
  EXPECT_EQ(model_to_safetensors(loaded).metadata.count("period_s"), 0u);
  expect_same_model(loaded, model);
}

TEST(ModelFile, PyTorchNamesAndShapes) {
  const st::File f = model_to_safetensors(sample_model(true));
  // hidden 8, x 6, u 2, y 4, pb 2, 2 states.
  const std::map<std::string, std::vector<std::int64_t>> want = {
      {"enc.weight", {8, 8}},          {"enc.bias", {8}},
      {"enc_bn.weight", {8}},          {"enc_bn.bias", {8}},
      {"enc_bn.running_mean", {8}},    {"enc_bn.running_var", {8}},
      {"enc_bn.num_batches_tracked", {}},
      {"lstm.weight_ih_l0", {32, 4}},  {"lstm.weight_hh_l0", {32, 8}},
      {"lstm.bias_ih_l0", {32}},       {"lstm.bias_hh_l0", {32}},
      {"dec.weight", {4, 8}},          {"dec.bias", {4}},
      {"pb", {2, 2}}};
  for (const auto& [name, shape] : want) {
    ASSERT_EQ(f.tensors.count(name), 1u) << name;
    EXPECT_EQ(f.tensors.at(name).shape, shape) << name;
  }
  EXPECT_EQ(f.metadata.at("format"), kModelFormat);
  // This model's sensor model has a calibration curve: version 2; without one, 1.
  EXPECT_EQ(f.metadata.at("format_version"), std::to_string(kModelFormatVersionCurves));
  EXPECT_EQ(model_to_safetensors(sample_model(false)).metadata.at("format_version"),
            std::to_string(kModelFormatVersion));
}

TEST(ModelFile, InconsistentModelIsNotWritten) {
  HadynetModel model = sample_model(false);
  model.states.pop_back();  // 1 state name for 2 PB rows
  EXPECT_THROW(model_to_safetensors(model), std::invalid_argument);
}

class ModelFileRejects : public ::testing::Test {
 protected:
  TempDir dir_;
  HadynetModel model_ = sample_model(true);
  st::File good_ = model_to_safetensors(model_);
  std::string path_ = (dir_.path() / "bad.safetensors").string();

  // load_model of `file` written to disk must throw a ModelFileError that
  // starts with the path and contains `part`.
  void expect_rejected(const st::File& file, const std::string& part) {
    st::write_file(path_, file);
    expect_load_fails(part);
  }
  void expect_load_fails(const std::string& part) {
    try {
      load_model(path_);
      ADD_FAILURE() << "accepted; expected an error containing " << part;
    } catch (const ModelFileError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path_ + ": ", 0), 0u) << what;
      EXPECT_EQ(what.find(path_, 1), std::string::npos) << "path named twice: " << what;
      EXPECT_TRUE(contains(what, part)) << what << "\n  lacks: " << part;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a ModelFileError: " << e.what();
    }
  }
  // Sets element `index` of an F32 tensor.
  static void set_f32(st::File& f, const std::string& name, std::size_t index, float value) {
    std::memcpy(f.tensors.at(name).bytes.data() + index * sizeof(float), &value, sizeof value);
  }
  // Replaces the first occurrence of `from` in metadata `key` (must exist).
  static void edit_metadata(st::File& f, const std::string& key, const std::string& from,
                            const std::string& to) {
    std::string& value = f.metadata.at(key);
    const std::size_t pos = value.find(from);
    ASSERT_NE(pos, std::string::npos) << key << " = " << value;
    value.replace(pos, from.size(), to);
  }
};

TEST_F(ModelFileRejects, SensorModelOnAnUnknownChannelOrWithBadNumbers) {
  // Each edit of the "sensor" metadata, and the part of the error it must give.
  const struct {
    const char* from;
    const char* to;
    const char* error;
  } cases[] = {
      {"\"side\":-1", "\"side\":0", "output clip side"},
      {"\"channel\":\"", "\"channel\":\"no_", "not a y channel"},
      {"\"rail\"", "\"rial\"", "rail"},
      {"\"driver\":\"level\"", "\"driver\":\"heat\"", "driver 'heat'"},
      // A bias that grew with the reading (builds before the level driver): refused, not re-read.
      {"\"driver\":\"level\"", "\"driver\":\"load\"", "driver 'load' (a bias growing with the reading"},
      {"\"steps\":2", "\"steps\":0", "sensor delay 'steps' must be a whole number in 1 .. 4096, got 0"},
      {"\"crosstalk\":[", "\"crosstalk\":{\"a\":1},\"x\":[", "'crosstalk' is not an array"},
      {"\"clips\":", "\"hysteresis\":[],\"clips\":", "unknown part 'hysteresis'"},
  };
  for (const auto& c : cases) {
    st::File f = good_;
    edit_metadata(f, "sensor", c.from, c.to);
    expect_rejected(f, c.error);
  }
}

TEST_F(ModelFileRejects, HeldOutLogsWhoseByteCountsDoNotCutTheirTensor) {
  const struct {
    const char* from;
    const char* to;
    const char* error;
  } cases[] = {
      {"\"bytes\":1,", "\"bytes\":2,", "than tensor 'held_out_logs.text' holds (32)"},  // beyond its end
      {"\"bytes\":31", "\"bytes\":30", "holds 32 bytes, metadata 'held_out_logs' counts 31"},  // a byte left
      {"\"bytes\":31", "\"bytes\":0", "whole number in 1 .."},  // an empty log
      {"\"name\"", "\"nmae\"", "has no 'name'"},
  };
  for (const auto& c : cases) {
    st::File f = good_;
    edit_metadata(f, "held_out_logs", c.from, c.to);
    expect_rejected(f, c.error);
  }
  st::File no_tensor = good_;
  no_tensor.tensors.erase("held_out_logs.text");
  expect_rejected(no_tensor, "without tensor 'held_out_logs.text'");
  st::File no_metadata = good_;
  no_metadata.metadata.erase("held_out_logs");
  expect_rejected(no_metadata, "unexpected tensor 'held_out_logs.text'");
}

TEST_F(ModelFileRejects, TheUnmodifiedFileLoads) {
  st::write_file(path_, good_);
  expect_same_model(load_model(path_), model_);
}

TEST_F(ModelFileRejects, WrongFormatTag) {
  st::File f = good_;
  f.metadata["format"] = "hadynet-log";
  expect_rejected(f, "not a HADYNET model");
  f.metadata.erase("format");
  expect_rejected(f, "not a HADYNET model");
}

TEST_F(ModelFileRejects, UnsupportedFormatVersion) {
  st::File f = good_;
  f.metadata["format_version"] = "3";
  expect_rejected(f, "format_version '3'; this build reads versions 1 and 2");
  // Version 1 cannot hold calibration curves: a build that reads only 1 would drop them.
  f.metadata["format_version"] = "1";
  expect_rejected(f, "calibration curves, which need format_version 2");
  f.metadata["format_version"] = "1.0";
  expect_rejected(f, "format_version '1.0'");
}

TEST_F(ModelFileRejects, MissingTensor) {
  for (const std::string name : {"lstm.bias_hh_l0", "pb", "norm.y_std", "detect.inverse",
                                 "enc_bn.num_batches_tracked"}) {
    st::File f = good_;
    f.tensors.erase(name);
    expect_rejected(f, "'" + name + "'");
  }
}

TEST_F(ModelFileRejects, WrongShapeOrDtype) {
  st::File f = good_;
  const std::vector<float> v(36, 0.5f);
  f.tensors["dec.weight"] = st::make_f32({4, 9}, v);
  expect_rejected(f, "'dec.weight' has shape [4, 9]");

  f = good_;
  f.tensors["pb"] = st::make_f32({4}, std::span<const float>(v.data(), 4));  // flattened [2, 2]
  expect_rejected(f, "'pb' has shape [4]");

  f = good_;
  const std::vector<std::int32_t> ints(8, 1);
  f.tensors["enc.bias"] = st::make_i32({8}, ints);
  expect_rejected(f, "'enc.bias' has dtype I32");

  f = good_;
  f.tensors["enc_bn.num_batches_tracked"] = st::make_i32({}, std::span<const std::int32_t>(ints.data(), 1));
  expect_rejected(f, "num_batches_tracked");
}

TEST_F(ModelFileRejects, UnexpectedExtraTensor) {
  st::File f = good_;
  f.tensors["extra.w"] = st::make_f32({1}, std::vector<float>{0.0f});
  expect_rejected(f, "unexpected tensor 'extra.w'");

  // Optimiser state: rejected by a model load, accepted only on request.
  f = good_;
  f.tensors["optim.adam.m.pb"] = st::make_f32({4}, std::vector<float>(4, 0.0f));
  expect_rejected(f, "unexpected tensor 'optim.adam.m.pb'");
  expect_same_model(model_from_safetensors(f, "mem", /*allow_optimizer_state=*/true), model_);

  // Detection tensors without the detection metadata are extra too.
  f = good_;
  f.metadata.erase("detection");
  expect_rejected(f, "unexpected tensor 'detect.");
}

TEST_F(ModelFileRejects, NonFiniteValues) {
  st::File f = good_;
  set_f32(f, "lstm.weight_hh_l0", 3, std::numeric_limits<float>::quiet_NaN());
  expect_rejected(f, "'lstm.weight_hh_l0' holds a non-finite value");

  f = good_;
  set_f32(f, "pb", 3, std::numeric_limits<float>::infinity());
  expect_rejected(f, "'pb' holds a non-finite value");

  f = good_;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(f.tensors.at("norm.u_mean").bytes.data(), &nan, sizeof nan);
  expect_rejected(f, "norm.u_mean");

  f = good_;
  std::memcpy(f.tensors.at("detect.covariance").bytes.data() + 8, &nan, sizeof nan);
  expect_rejected(f, "detect.covariance holds nan at flat index");
}

TEST_F(ModelFileRejects, ChannelsWhoseXDoesNotFollowFromYAndDeltaGroups) {
  st::File f = good_;
  edit_metadata(f, "channels", R"("dq0","dq1")", R"("dq1","dq0")");
  expect_rejected(f, "x does not follow from y and delta_groups");

  f = good_;
  edit_metadata(f, "channels", R"("delta_groups":["q"])", R"("delta_groups":[])");
  expect_rejected(f, "x does not follow from y and delta_groups");

  f = good_;  // a delta group that is not observed
  edit_metadata(f, "channels", R"("delta_groups":["q"])", R"("delta_groups":["q","l"])");
  expect_rejected(f, "delta group 'l'");
}

TEST_F(ModelFileRejects, DimsNotMatchingTheTensorsOrChannels) {
  st::File f = good_;
  edit_metadata(f, "dims", R"("hidden":8)", R"("hidden":9)");
  expect_rejected(f, "'enc.weight' has shape [8, 8], expected [9, 8]");

  f = good_;
  edit_metadata(f, "dims", R"("states":2)", R"("states":3)");
  expect_rejected(f, "'pb' has shape [2, 2], expected [3, 2]");

  // Tensors and dims agree (one more y channel) but the channel list does not.
  f = good_;
  edit_metadata(f, "dims", R"("y":4)", R"("y":5)");
  f.tensors["dec.weight"] = st::make_f32({5, 8}, std::vector<float>(40, 0.1f));
  f.tensors["dec.bias"] = st::make_f32({5}, std::vector<float>(5, 0.1f));
  f.tensors["norm.y_mean"] = st::make_f64({5}, std::vector<double>(5, 0.0));
  f.tensors["norm.y_std"] = st::make_f64({5}, std::vector<double>(5, 1.0));
  f.tensors["detect.mean"] = st::make_f64({5}, std::vector<double>(5, 0.0));
  f.tensors["detect.covariance"] = st::make_f64({5, 5}, std::vector<double>(25, 0.0));
  f.tensors["detect.inverse"] = st::make_f64({5, 5}, std::vector<double>(25, 0.0));
  expect_rejected(f, "y channels differ from dims.y");

  f = good_;
  edit_metadata(f, "dims", R"("pb":2)", R"("pb":0)");
  expect_rejected(f, "metadata 'dims'");
}

// Issue 19, finding 7: sizes that overflow, wrap or promise more than the
// file holds are refused by name before anything of that size is allocated,
// and finite but absurd numbers are refused as codegen refuses them.
TEST_F(ModelFileRejects, SizesThatOverflowWrapOrExceedTheFile) {
  const struct {
    const char* from;
    const char* to;
    const char* error;
  } cases[] = {
      // Was accepted: signed overflow in the window code, then bad_alloc.
      {R"("train_steps":5)", R"("train_steps":2147483647)",
       "metadata 'dims' 'train_steps' must be a whole number in 1 .. 4096, got 2147483647"},
      // Was accepted as 37 (4294967333 mod 2^32).
      {R"("x":)", R"("x":4294967333,"x_old":)", "metadata 'dims' 'x' must be a whole number in 1 .. 8192, got 4294967333"},
      {R"("hidden":8)", R"("hidden":65536)", "metadata 'dims' 'hidden' must be a whole number in 1 .. 1024, got 65536"},
      {R"("hidden":8)", R"("hidden":8.5)", "metadata 'dims' 'hidden' must be a whole number"},
      {R"("states":2)", R"("states":100001)", "'states' must be a whole number in 1 .. 100000"},
      // Within the limits, but the file's tensors cannot hold that model:
      // refused before zeroing hidden^2 floats.
      {R"("hidden":8)", R"("hidden":1000)", "float32 parameters; the file's tensors hold"},
  };
  for (const auto& c : cases) {
    st::File f = good_;
    edit_metadata(f, "dims", c.from, c.to);
    expect_rejected(f, c.error);
  }
}

TEST_F(ModelFileRejects, FiniteButAbsurdNumbers) {
  st::File f = good_;
  const double denormal = 4e-320;
  std::memcpy(f.tensors.at("norm.y_std").bytes.data(), &denormal, sizeof denormal);
  expect_rejected(f, "norm.y_std holds");  // adapt printed a -nan PB with it

  f = good_;
  const double huge = 1e300;
  std::memcpy(f.tensors.at("norm.u_mean").bytes.data(), &huge, sizeof huge);
  expect_rejected(f, "norm.u_mean holds");

  f = good_;
  set_f32(f, "dec.weight", 3, 3e38f);
  expect_rejected(f, "tensor 'dec.weight' holds");

  f = good_;
  edit_metadata(f, "sensor", R"("gain":)", R"("gain":1e308,"gain_old":)");
  expect_rejected(f, "sensor crosstalk 'gain' must be a number in -1 .. 1, got 1e+308");

  f = good_;
  edit_metadata(f, "sensor", R"("rate":)", R"("rate":1e308,"rate_old":)");
  expect_rejected(f, "sensor drift 'rate' must be a number in -1e+30 .. 1e+30");
}

TEST_F(ModelFileRejects, InconsistentOrMalformedMetadata) {
  st::File f = good_;
  f.metadata["states"] = R"([{"name":"soft","object":"ball"}])";  // one name, two PB rows
  expect_rejected(f, "PB states differ from the PB table rows");

  f = good_;
  f.metadata["states"] = "[{";
  expect_rejected(f, "'states' is not valid JSON");

  f = good_;
  f.metadata["states"] = R"([{"name":3,"object":""},{"name":"b","object":""}])";
  expect_rejected(f, "'name' has the wrong type");

  f = good_;
  f.metadata["hyper_parameters"] = R"({"lr":0.01})";  // values must be strings
  expect_rejected(f, "");

  f = good_;
  f.metadata.erase("channels");
  expect_rejected(f, "metadata has no 'channels'");

  for (const char* bad : {"0", "-0.2", "\"0.2\"", "1e9"}) {
    f = good_;
    f.metadata["period_s"] = bad;
    expect_rejected(f, "'period_s'");
  }

  f = good_;
  edit_metadata(f, "detection", R"("threshold":4.25)", R"("threshold":-1.0)");
  expect_rejected(f, "detection 'threshold' must be a number in 0 .. 1e+30, got -1");

  f = good_;
  const double zero = 0.0;
  std::memcpy(f.tensors.at("norm.x_std").bytes.data(), &zero, sizeof zero);
  expect_rejected(f, "a standardisation std must be at least 1e-12");
}

TEST_F(ModelFileRejects, MalformedRanges) {
  ASSERT_EQ(good_.metadata.count("ranges"), 1u);
  st::File f = good_;
  f.metadata["ranges"] = "[1, 2]";
  expect_rejected(f, "ranges has no 'x'");

  f = good_;
  edit_metadata(f, "ranges", R"("h":)", R"("h":-)");
  expect_rejected(f, "ranges 'h' must be a number in 0 .. 1e+30");

  f = good_;
  edit_metadata(f, "ranges", R"("windows":321)", R"("windows":"many")");
  expect_rejected(f, "ranges 'windows' must be a whole number in 0 .. 9007199254740992, got \"many\"");

  f = good_;
  edit_metadata(f, "ranges", R"("c":)", R"("c_old":)");
  expect_rejected(f, "ranges has no 'c'");

  HadynetModel m = model_;
  m.ranges->y = std::numeric_limits<double>::infinity();
  EXPECT_THROW(model_to_safetensors(m), std::invalid_argument);
}

TEST_F(ModelFileRejects, TruncatedFile) {
  const std::string bytes = st::serialize(good_);
  for (const std::size_t keep : {bytes.size() - 1, bytes.size() / 2, std::size_t{5}}) {
    {
      std::ofstream out(path_, std::ios::binary | std::ios::trunc);
      out.write(bytes.data(), static_cast<std::streamsize>(keep));
    }
    expect_load_fails("");
  }
}

TEST_F(ModelFileRejects, NonModelSafetensorsFile) {
  st::File f;
  f.metadata["framework"] = "pt";
  f.tensors["weight"] = st::make_f32({2, 2}, std::vector<float>{1, 2, 3, 4});
  expect_rejected(f, "not a HADYNET model");
}

TEST_F(ModelFileRejects, MissingFile) {
  path_ = (dir_.path() / "absent.safetensors").string();
  expect_load_fails("");
}

}  // namespace
}  // namespace hadynet::trainer::testing
