// Codegen (codegen/codegen.h): the format rule, the whitening matrix, the
// rejection of unsupported models (in the library and at the command line,
// where nothing may be written), and determinism. The generated header of the
// build's default model is checked value by value in default_model_test.cc.
#include "codegen/codegen.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include "codegen/header_text.h"
#include "codegen/sensor_arrays.h"
#include "firmware/core/fixed_point.h"
#include "trainer/deploy_prep.h"
#include "trainer/detection.h"
#include "trainer/model_file.h"
#include "test/codegen/synthetic_model.h"

namespace hadynet::codegen {
namespace {

namespace fs = std::filesystem;
using trainer::HadynetModel;
using test::synthetic_model;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// ---- the format rule ---------------------------------------------------------

TEST(FormatRule, PowersOfTwoLeaveRoomForTheRoundedExtreme) {
  // m = 2^k needs 2^k 2^F <= 32767, so F = 14 - k (2^15 itself does not fit).
  EXPECT_EQ(frac_bits_for(1.0), 14);
  EXPECT_EQ(frac_bits_for(2.0), 13);
  EXPECT_EQ(frac_bits_for(4.0), 12);
  EXPECT_EQ(frac_bits_for(8192.0), 1);
  EXPECT_EQ(frac_bits_for(16384.0), 0);
  // Below 1, Q15 holds m up to 32767/32768.
  EXPECT_EQ(frac_bits_for(0.5), 15);
  EXPECT_EQ(frac_bits_for(0.25), 15);
  EXPECT_EQ(frac_bits_for(0.99998), 15);  // round(32767.34) = 32767
  EXPECT_EQ(frac_bits_for(0.99999), 14);  // round(32767.67) = 32768: one bit less
  EXPECT_EQ(frac_bits_for(3.0), 13);      // 3 x 2^13 = 24576
}

TEST(FormatRule, ZeroTinyAndHuge) {
  EXPECT_EQ(frac_bits_for(0.0), 15);
  EXPECT_EQ(frac_bits_for(1e-30), 15);
  EXPECT_EQ(frac_bits_for(std::numeric_limits<double>::denorm_min()), 15);
  EXPECT_EQ(frac_bits_for(32767.0), 0);
  EXPECT_EQ(frac_bits_for(32767.49), 0);
  EXPECT_THROW(frac_bits_for(32767.5), UnsupportedModel);  // rounds to 32768
  EXPECT_THROW(frac_bits_for(1e6), UnsupportedModel);
  EXPECT_THROW(frac_bits_for(-1.0), UnsupportedModel);
  EXPECT_THROW(frac_bits_for(std::nan("")), UnsupportedModel);
  EXPECT_THROW(frac_bits_for(std::numeric_limits<double>::infinity()), UnsupportedModel);
  try {
    frac_bits_for(1e6, "kFracY");
  } catch (const UnsupportedModel& e) {
    EXPECT_TRUE(contains(e.what(), "kFracY")) << e.what();
  }
}

TEST(FormatRule, IsTheLargestFractionThatHoldsTheExtreme) {
  // Property over magnitudes spread across the whole range: m fits Q(F), and
  // Q(F+1) would not hold it (or F is already 15).
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> exponent(-20.0, 14.99);
  for (int i = 0; i < 20000; ++i) {
    const double m = std::exp2(exponent(rng));
    const int f = frac_bits_for(m);
    ASSERT_GE(f, 0);
    ASSERT_LE(f, 15);
    const auto raw = [m](int frac) { return fixed::real_to_fixed<std::int64_t, 0>(std::ldexp(m, frac)); };
    ASSERT_LE(raw(f), 32767) << m;
    if (f < 15) {
      ASSERT_GT(raw(f + 1), 32767) << m;
    }
  }
}

TEST(FormatRule, ToFixedIsTheFirmwaresRealToFixed) {
  // Ties away from zero, as firmware/core/fixed_point.h.
  EXPECT_EQ(to_fixed(2.5, 0), 3);
  EXPECT_EQ(to_fixed(-2.5, 0), -3);
  EXPECT_EQ(to_fixed(2.4, 0), 2);
  EXPECT_EQ(to_fixed(0.1, 15), (fixed::real_to_fixed<std::int64_t, 15>(0.1)));
  EXPECT_EQ(to_fixed(-1.7, 30), (fixed::real_to_fixed<std::int64_t, 30>(-1.7)));
  EXPECT_EQ(to_fixed(3.0, 62), (fixed::real_to_fixed<std::int64_t, 62>(3.0)));  // saturates
  EXPECT_THROW(to_fixed(1.0, 63), std::invalid_argument);
}

const ModelIdentity kIdentity{"synthetic.safetensors", 0x0123456789abcdefULL};

GeneratedHeader generate_q15(const HadynetModel& m, CodegenOptions o = {}) {
  o.numeric = Numeric::kQ15;
  return generate(m, kIdentity, o);
}

// generate() must throw UnsupportedModel whose message contains `part`.
void expect_unsupported(const HadynetModel& m, const CodegenOptions& o, const std::string& part) {
  try {
    generate(m, kIdentity, o);
    ADD_FAILURE() << "accepted; expected an error containing '" << part << "'";
  } catch (const UnsupportedModel& e) {
    EXPECT_TRUE(contains(e.what(), part)) << e.what() << "\n  lacks: " << part;
  }
}

// ---- formats of a model -------------------------------------------------------

TEST(Formats, FollowTheRangesWithHeadroomOnActivationsOnly) {
  HadynetModel m = synthetic_model(true);
  CodegenOptions o;
  o.headroom = 1.0;
  const Formats f1 = choose_formats(m, o);
  EXPECT_EQ(f1.h.frac, 15);  // 0.9
  EXPECT_EQ(f1.c.frac, 14);  // 1.7
  EXPECT_EQ(f1.in.frac, 13); // max(2.5, 1.2, |PB| < 0.8, 0.3, alpha 1) = 2.5
  EXPECT_EQ(f1.y.frac, 13);  // 3.1
  o.headroom = 2.0;
  const Formats f2 = choose_formats(m, o);
  EXPECT_EQ(f2.h.frac, 14);  // 1.8
  EXPECT_EQ(f2.c.frac, 13);  // 3.4
  EXPECT_EQ(f2.in.frac, 12); // 5.0
  EXPECT_EQ(f2.y.frac, 12);  // 6.2
  // Weights and fixed formats do not depend on the headroom.
  EXPECT_EQ(f2.enc_w.frac, f1.enc_w.frac);
  EXPECT_EQ(f2.lstm_w.frac, f1.lstm_w.frac);
  EXPECT_EQ(f2.dec_w.frac, f1.dec_w.frac);
  EXPECT_EQ(f2.whiten.frac, f1.whiten.frac);
  EXPECT_EQ(f2.z.frac, f1.z.frac);
  EXPECT_EQ(f2.lstm_acc.frac, f2.lstm_w.frac + std::max(f2.in.frac, f2.h.frac));
  EXPECT_EQ(f2.gate.frac, 12);
  EXPECT_EQ(f2.loss_w.frac, 14);  // physical units: weights normalised to a largest of 1.0
  EXPECT_EQ(f2.z.frac, frac_bits_for(4.0 * 5.0));  // |z| up to 4 C_detect
  // The PB table and the alphas count in kFracIn without headroom.
  m.ranges->x = m.ranges->u = 0.0;
  o.control.alphas = {3.0, 1.0};
  EXPECT_EQ(choose_formats(m, o).in.frac, 13);  // alpha 3
}

TEST(Formats, AnF32ModelHasNone) {
  CodegenOptions o;
  o.numeric = Numeric::kF32;
  const Formats f = choose_formats(synthetic_model(true), o);
  EXPECT_EQ(f.in.frac, 0);
  EXPECT_EQ(f.lstm_acc.frac, 0);
  const GeneratedHeader h = generate(synthetic_model(true), kIdentity, o);
  EXPECT_TRUE(contains(h.text, "static constexpr int kFracIn = 0;"));
  EXPECT_TRUE(contains(h.text, "using Value = float;"));
}

// ---- rejection ------------------------------------------------------------------

TEST(Rejects, MissingRanges) {
  HadynetModel m = synthetic_model(true);
  m.ranges.reset();
  expect_unsupported(m, {}, "no measured value ranges");
  CodegenOptions f32;
  f32.numeric = Numeric::kF32;
  expect_unsupported(m, f32, "no measured value ranges");
}

TEST(Rejects, EmptyDimensions) {
  HadynetModel m = synthetic_model(true);
  m.params.dims.pb = 0;  // the tensors no longer follow the dimensions either
  expect_unsupported(m, {}, "pb");
  m = synthetic_model(false);
  m.train_steps = 0;
  expect_unsupported(m, {}, "train_steps < 1");
}

TEST(Rejects, StaleRanges) {
  HadynetModel m = synthetic_model(true);
  m.params.dec_weight(0, 0) = 10.0f;
  expect_unsupported(m, {}, "measured with other weights");
}

TEST(Rejects, NonFiniteValues) {
  HadynetModel m = synthetic_model(true);
  m.params.lstm_weight_hh(3, 2) = std::numeric_limits<float>::quiet_NaN();
  expect_unsupported(m, {}, "'lstm.weight_hh_l0' holds a non-finite value");
  m = synthetic_model(true);
  m.detection->mean(1) = std::numeric_limits<double>::infinity();
  expect_unsupported(m, {}, "detection statistics are not finite");
  m = synthetic_model(true);
  m.ranges->c = std::nan("");
  expect_unsupported(m, {}, "range 'c'");
}

TEST(Rejects, Int32BiasOverflow) {
  // The encoder bias is Q(kFracEncW + kFracIn) = Q(>= 26) here: ~800 (folded)
  // is beyond 2^31 / 2^26 = 32.
  HadynetModel m = synthetic_model(true);
  m.params.enc_bias(2) = 1000.0f;
  m.params.enc_bn_running_mean(2) = 0.0f;
  try {
    generate_q15(m);
    ADD_FAILURE() << "bias overflow accepted";
  } catch (const UnsupportedModel& e) {
    EXPECT_TRUE(contains(e.what(), "kEncBias[2]")) << e.what();
    EXPECT_TRUE(contains(e.what(), "overflows int32")) << e.what();
  }
  // The same model as float32 has no such limit.
  CodegenOptions f32;
  f32.numeric = Numeric::kF32;
  EXPECT_NO_THROW(generate(m, kIdentity, f32));
}

TEST(Rejects, RangeBeyondInt16) {
  HadynetModel m = synthetic_model(true);
  m.ranges->y = 30000.0;  // x 1.5 headroom = 45000 > 32767 even in Q0
  expect_unsupported(m, {}, "kFracY");
}

TEST(Rejects, ControlHorizon) {
  const HadynetModel m = synthetic_model(true);
  CodegenOptions o;
  o.control.horizon = 11;  // N_train is 10
  expect_unsupported(m, o, "control horizon 11 must be in 1 .. N_train 10");
  o.control.horizon = 0;
  expect_unsupported(m, o, "control horizon 0");
  o.control.horizon = 10;
  EXPECT_NO_THROW(generate(m, kIdentity, o));
  o.control.truncation = 0;
  expect_unsupported(m, o, "truncation");
  o.control.truncation = 3;
  EXPECT_TRUE(contains(generate(m, kIdentity, o).text, "kControlTruncation = 3;"));
  o.control.epochs = 0;
  expect_unsupported(m, o, "epochs");
}

TEST(Rejects, BadAlphas) {
  const HadynetModel m = synthetic_model(true);
  for (const std::vector<double>& alphas :
       std::vector<std::vector<double>>{{}, {1.0, 0.0}, {-0.5}, {std::nan("")}, {1e300}}) {
    CodegenOptions o;
    o.control.alphas = alphas;
    EXPECT_THROW(generate(m, kIdentity, o), UnsupportedModel) << alphas.size();
  }
  CodegenOptions o;
  o.control.alphas = {1.0, 1e-6};  // below half an LSB of kFracIn = 12
  expect_unsupported(m, o, "below half an LSB");
  o.numeric = Numeric::kF32;  // fine as float
  EXPECT_NO_THROW(generate(m, kIdentity, o));
}

TEST(Rejects, LossGroupsAndWeights) {
  const HadynetModel m = synthetic_model(true);
  CodegenOptions o;
  o.control.angle_groups = std::vector<std::string>{"wrist"};
  expect_unsupported(m, o, "angle loss group 'wrist' names no y channel");
  o = {};
  o.control.force_groups = std::vector<std::string>{"f"};
  o.control.length_groups = std::vector<std::string>{"l", "f"};  // f is a force group too
  expect_unsupported(m, o, "loss group 'f' is in both");
  o = {};
  o.control.loss.physical_units = false;
  o.control.loss.beta = 8.0;  // standardised units: Q12 holds up to 7.99976
  expect_unsupported(m, o, "loss weight beta");
  o = {};
  o.control.commands = std::vector<std::string>{"u0", "nope"};
  expect_unsupported(m, o, "control command 'nope' is not a u channel");
  o = {};
  o.control.loss.w2 = -1.0;
  expect_unsupported(m, o, "loss weight w2");
}

TEST(Rejects, BadOptionsAndDetection) {
  HadynetModel m = synthetic_model(true);
  CodegenOptions o;
  for (const std::string ns : {"1model", "hadynet::", "a::class", "a:b", "__x", "a b"}) {
    o.ns = ns;
    expect_unsupported(m, o, "is not a C++ namespace name");
  }
  o = {};
  o.headroom = 0.5;
  expect_unsupported(m, o, "headroom");
  m.detection->steps = 11;
  expect_unsupported(m, {}, "N_detect 11");
  m = synthetic_model(true);
  m.detection->inverse(0, 0) = -5.0;
  expect_unsupported(m, {}, "not positive definite");
}

// ---- the generated text -------------------------------------------------------

TEST(Generate, IsDeterministic) {
  const HadynetModel m = synthetic_model(true);
  for (const Numeric n : {Numeric::kQ15, Numeric::kF32}) {
    CodegenOptions o;
    o.numeric = n;
    const GeneratedHeader a = generate(m, kIdentity, o);
    const GeneratedHeader b = generate(synthetic_model(true), kIdentity, o);
    EXPECT_EQ(a.text, b.text);
    EXPECT_EQ(a.file_name, header_file_name(n));
  }
}

TEST(Generate, ContentsOfASmallModel) {
  CodegenOptions standardised;
  standardised.control.loss.physical_units = false;
  const GeneratedHeader h = generate_q15(synthetic_model(true), standardised);
  const std::string& t = h.text;
  EXPECT_EQ(h.file_name, "hadynet_model_q15.h");
  EXPECT_TRUE(contains(t, "namespace hadynet::model_q15 {"));
  EXPECT_TRUE(contains(t, "kModelHash = 0x0123456789abcdefULL;"));
  EXPECT_TRUE(contains(t, "// Model      synthetic.safetensors, FNV-1a 64 0x0123456789abcdef"));
  EXPECT_TRUE(contains(t, "static constexpr bool kHasDetection = true;"));
  EXPECT_TRUE(contains(t, "static constexpr int kDetectSteps = 3;"));
  // Escaped strings: the quotes in the object label.
  EXPECT_TRUE(contains(t, R"("Hammer \"big\"")"));
  // Loss classes by group: l0 l1 length, f0 fc0 fc1 force, th0 angle.
  EXPECT_TRUE(contains(t, "hadynet::firmware::LossClass::kLength, hadynet::firmware::LossClass::kLength,"));
  // Force weights: up 1, down beta 3 (Q12); angle and length 1.
  EXPECT_TRUE(contains(t, "kLossWeightUp[kY] = {\n      4096, 4096, 4096, 4096, 4096, 4096};"));
  EXPECT_TRUE(contains(t, "kLossWeightDown[kY] = {\n      4096, 4096, 12288, 12288, 12288, 4096};"));
  // C_detect = 5, kFracZ = frac_bits_for(20) = 10: 25 x 2^20.
  EXPECT_TRUE(contains(t, "kDetectThresholdSq = 26214400;"));
  // It ends with the contract check, then closes the namespace and the guard.
  EXPECT_TRUE(contains(t, "static_assert(hadynet::firmware::GeneratedModel<Model>);\n\n}  // namespace"));
  for (const std::string& line : {std::string("#include <cstdint>"),
                                  std::string("#include \"firmware/core/model_contract.h\"")}) {
    EXPECT_TRUE(contains(t, line)) << line;
  }
  // Only those two includes; lines stay short.
  std::size_t includes = 0, pos = 0;
  while ((pos = t.find("#include", pos)) != std::string::npos) ++includes, ++pos;
  EXPECT_EQ(includes, 2u);
  std::istringstream lines(t);
  for (std::string line; std::getline(lines, line);) EXPECT_LE(line.size(), 100u) << line;
}

TEST(Generate, AModelWithoutDetection) {
  const GeneratedHeader h = generate_q15(synthetic_model(false));
  EXPECT_TRUE(contains(h.text, "static constexpr bool kHasDetection = false;"));
  EXPECT_TRUE(contains(h.text, "static constexpr int kDetectSteps = 1;"));
  EXPECT_TRUE(contains(h.text, "kDetectThresholdSq = 0;"));
  EXPECT_EQ(h.formats.whiten.frac, 15);
  EXPECT_EQ(h.formats.z.frac, 15);
}

TEST(Generate, CustomNamespace) {
  CodegenOptions o;
  o.ns = "robot::hand_v2";
  const GeneratedHeader h = generate_q15(synthetic_model(true), o);
  EXPECT_TRUE(contains(h.text, "namespace robot::hand_v2 {"));
  EXPECT_TRUE(contains(h.text, "#ifndef HADYNET_GENERATED_ROBOT_HAND_V2_Q15_H_"));
}

// ---- the command line: nothing is written for a rejected model ----------------

class CodegenTool : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "hadynet_codegen_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    out_ = dir_ / "out";
    fs::create_directories(out_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  // Runs hadynet-codegen with `args`; returns its exit code.
  int run(const std::string& args) const {
    const std::string cmd = "'" + std::string(HADYNET_CODEGEN_TOOL) + "' " + args + " > " +
                            (dir_ / "stdout").string() + " 2> " + (dir_ / "stderr").string();
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  std::string read(const fs::path& p) const {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  std::string save(const HadynetModel& m, const std::string& name) const {
    const std::string path = (dir_ / name).string();
    trainer::save_model(path, m);
    return path;
  }
  bool out_empty() const { return fs::is_empty(out_); }

  fs::path dir_, out_;
};

TEST_F(CodegenTool, WritesTheHeaderOfGenerate) {
  const std::string model = save(synthetic_model(true), "m.safetensors");
  ASSERT_EQ(run(model + " --numeric q15 --out " + out_.string()), 0) << read(dir_ / "stderr");
  const std::string text = read(out_ / "hadynet_model_q15.h");
  // The tool's text is generate() of the file it read, hash included.
  const LoadedModel loaded = load_model_file(model);
  EXPECT_EQ(text, generate(loaded.model, loaded.identity, CodegenOptions{}).text);
  EXPECT_TRUE(contains(read(dir_ / "stdout"), "kFracIn"));
  // Again: the same text, the file is left as it is.
  ASSERT_EQ(run(model + " --numeric q15 --out " + out_.string()), 0);
  EXPECT_TRUE(contains(read(dir_ / "stdout"), "unchanged"));
  EXPECT_EQ(read(out_ / "hadynet_model_q15.h"), text);
  // No temporary files are left behind.
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(out_)) ++files;
  EXPECT_EQ(files, 1u);
}

TEST_F(CodegenTool, RejectedModelsWriteNothing) {
  HadynetModel no_ranges = synthetic_model(true);
  no_ranges.ranges.reset();
  HadynetModel nan_weight = synthetic_model(true);
  nan_weight.params.dec_weight(1, 1) = std::numeric_limits<float>::quiet_NaN();
  HadynetModel big_bias = synthetic_model(true);
  big_bias.params.lstm_bias_ih(4) = 500.0f;
  const std::string good = save(synthetic_model(true), "good.safetensors");
  const std::string out = " --out " + out_.string();
  struct Case {
    std::string args;
    int code;
    std::string message;
  };
  const Case cases[] = {
      {save(no_ranges, "no_ranges.safetensors") + " --numeric q15" + out, 1, "no measured value ranges"},
      {save(nan_weight, "nan.safetensors") + " --numeric f32" + out, 1, "non-finite"},
      {save(big_bias, "bias.safetensors") + " --numeric q15" + out, 1, "kLstmBias[4]"},
      {good + " --numeric q15 --control-horizon 11" + out, 1, "control horizon 11"},
      {good + " --numeric q15 --control-alphas 1,0" + out, 1, "control alpha 0 is not positive"},
      {good + " --numeric q15 --control-alphas 1,x" + out, 2, "--control-alphas"},
      {good + " --numeric q16" + out, 2, "--numeric must be q15 or f32"},
      {good + " --numeric q15 --namespace 9x" + out, 1, "not a C++ namespace"},
      {good + " --numeric q15", 2, "give MODEL, --numeric and --out"},
      {(dir_ / "missing.safetensors").string() + " --numeric q15" + out, 1, "missing.safetensors"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(run(c.args), c.code) << c.args;
    EXPECT_TRUE(contains(read(dir_ / "stderr"), c.message)) << read(dir_ / "stderr");
    EXPECT_TRUE(out_empty()) << c.args;
  }
  // An output directory that does not exist yet is not created either.
  EXPECT_EQ(run(save(no_ranges, "x.safetensors") + " --numeric q15 --out " + (dir_ / "new").string()), 1);
  EXPECT_FALSE(fs::exists(dir_ / "new"));
}

TEST_F(CodegenTool, HelpOfBothTools) {
  EXPECT_EQ(run("--help"), 0);
  EXPECT_TRUE(contains(read(dir_ / "stdout"), "usage: hadynet-codegen MODEL"));
  const std::string measure = "'" + std::string(HADYNET_MEASURE_RANGES_TOOL) + "' --help > " +
                              (dir_ / "stdout").string() + " 2> " + (dir_ / "stderr").string();
  EXPECT_EQ(WEXITSTATUS(std::system(measure.c_str())), 0);
  EXPECT_TRUE(contains(read(dir_ / "stdout"), "usage: hadynet-measure-ranges MODEL"));
}

// hadynet-codegen links no trainer network (its output must not depend on
// the machine): --logs is a usage error that says where it is.
TEST_F(CodegenTool, LogsAreForTheToolsThatMeasure) {
  EXPECT_EQ(run("model.safetensors --numeric q15 --out " + (dir_ / "gen").string() + " --logs a.log"), 2);
  EXPECT_TRUE(contains(read(dir_ / "stderr"), "hadynet-measure-ranges")) << read(dir_ / "stderr");
  EXPECT_TRUE(contains(read(dir_ / "stderr"), "hadynet codegen --logs")) << read(dir_ / "stderr");
  EXPECT_FALSE(fs::exists(dir_ / "gen"));
}

// The numbers of a generated `static constexpr ... name[...] = {a, b, ...};`.
std::vector<double> array_values(const std::string& text, const std::string& name) {
  const auto at = text.find(name);
  const auto open = text.find('{', at);
  const auto close = text.find('}', open);
  std::vector<double> v;
  std::string item;
  for (std::size_t i = open + 1; i <= close; ++i) {
    const char ch = text[i];
    if (ch == ',' || ch == '}') {
      if (!item.empty()) v.push_back(std::stod(item));
      item.clear();
    } else if (ch != ' ' && ch != '\n' && ch != 'f') {
      item += ch;
    }
  }
  return v;
}

// Physical units (the default): weight_i = class weight x std_i^2, scaled so
// that the largest is 1; exact in f32 up to float rounding (1e-6 relative),
// within half an LSB of Q14 in q15. Inactive commands are marked.
TEST(Generate, PhysicalLossWeightsFoldTheStdSquaredAndCommandsAreMasked) {
  const HadynetModel m = synthetic_model(true);
  CodegenOptions o;
  o.numeric = Numeric::kF32;
  o.control.loss.beta = 3.0;
  o.control.commands = std::vector<std::string>{m.layout.u_names.back()};
  const std::string f32 = generate(m, kIdentity, o).text;
  o.numeric = Numeric::kQ15;
  const std::string q15 = generate(m, kIdentity, o).text;
  const auto up = array_values(f32, "kLossWeightUp[kY]");
  const auto down = array_values(f32, "kLossWeightDown[kY]");
  const auto up_q = array_values(q15, "kLossWeightUp[kY]");
  ASSERT_EQ(up.size(), m.layout.y_names.size());
  double largest = 0;
  std::vector<double> want_up, want_down;
  for (std::size_t i = 0; i < up.size(); ++i) {
    const std::string g = trainer::channel_group(m.layout.y_names[i]);
    const double s2 = m.norm.y.std(static_cast<Eigen::Index>(i)) * m.norm.y.std(static_cast<Eigen::Index>(i));
    const bool force = g == "f" || g == "fc";
    want_up.push_back(s2);
    want_down.push_back(force ? 3.0 * s2 : s2);
    largest = std::max(largest, want_down.back());
  }
  for (std::size_t i = 0; i < up.size(); ++i) {
    EXPECT_NEAR(up[i], want_up[i] / largest, 1e-6) << m.layout.y_names[i];
    EXPECT_NEAR(down[i], want_down[i] / largest, 1e-6) << m.layout.y_names[i];
    EXPECT_LE(std::abs(up_q[i] / 16384.0 - want_up[i] / largest), 0.5 / 16384.0) << m.layout.y_names[i];
  }
  EXPECT_TRUE(contains(q15, "static constexpr int kFracLossW = 14;"));
  const auto active = std::string("kControlActive[kU] = {");
  EXPECT_TRUE(contains(f32, active)) << "no kControlActive";
  const std::string mask = f32.substr(f32.find(active), 200);
  EXPECT_TRUE(contains(mask, "false")) << mask;
  EXPECT_TRUE(contains(mask, "true}")) << mask;  // only the last command is active
}

}  // namespace
}  // namespace hadynet::codegen

namespace hadynet::codegen {
namespace {

// The stabiliser's commands and loss classes come from the model's robot
// profile unless options give them; a model without a profile has no loss
// classes (codegen then refuses it: nothing to minimise) until they are given.
TEST(Generate, TheRobotProfileGivesTheDefaultsAndOptionsOverrideIt) {
  HadynetModel m = synthetic_model(true);
  m.profile.control_commands = {"u1"};
  CodegenOptions o;
  EXPECT_TRUE(contains(generate(m, kIdentity, o).text, "--control-commands u1\n")) << "from the profile";
  o.control.commands = std::vector<std::string>{};
  EXPECT_TRUE(contains(generate(m, kIdentity, o).text, "--control-commands all\n")) << "all, given";

  m.profile = {};
  m.profile.delta_groups = m.layout.delta_groups;
  expect_unsupported(m, CodegenOptions{}, "every loss weight is zero");
  o = {};
  o.control.force_groups = std::vector<std::string>{"fc"};
  const std::string t = generate(m, kIdentity, o).text;
  EXPECT_TRUE(contains(t, "hadynet::firmware::LossClass::kForce")) << "given";
  EXPECT_FALSE(contains(t, "hadynet::firmware::LossClass::kLength")) << "not in the options, no profile";
}

// The control period and the board group come from the model (its logs'
// dt_s and robot profile); --period-s only fills in a period a model file
// does not record.
TEST(Generate, PeriodAndBoardGroupComeFromTheModel) {
  HadynetModel m = synthetic_model(true);
  m.profile.board_group = "fc";
  std::string t = generate(m, kIdentity, CodegenOptions{}).text;
  EXPECT_TRUE(contains(t, "static constexpr std::uint32_t kPeriodUs = 200000;"));
  EXPECT_TRUE(contains(t, "static constexpr char kBoardGroup[] = \"fc\";"));
  EXPECT_FALSE(contains(t, "--period-s")) << "the model's own period needs no option";

  CodegenOptions o;
  o.period_s = 0.1;
  EXPECT_THROW(generate(m, kIdentity, o), UnsupportedModel) << "another period than the model's";
  o.period_s = 0.2;
  EXPECT_NO_THROW(generate(m, kIdentity, o)) << "the same period";

  m.period_s = 0;  // a file from before models stored their period
  m.profile.board_group.clear();
  EXPECT_THROW(generate(m, kIdentity, CodegenOptions{}), UnsupportedModel);
  o.period_s = 0.05;
  t = generate(m, kIdentity, o).text;
  EXPECT_TRUE(contains(t, "kPeriodUs = 50000;"));
  EXPECT_TRUE(contains(t, "--period-s 0.05\n")) << "the regenerate line repeats the option";
  EXPECT_TRUE(contains(t, "static constexpr char kBoardGroup[] = \"\";")) << "no profile: no board channels";
  for (const double bad : {0.0, -1.0, std::nan("")}) {
    o.period_s = bad;
    EXPECT_THROW(generate(m, kIdentity, o), UnsupportedModel) << bad;
  }
}

// ---- the sensor model's calibration curves (trainer/sensor_model.h) ----------------

// The generated header's literals of one member.
std::vector<std::string> literal(const GeneratedHeader& h, const std::string& name) {
  const auto it = h.literals.find(name);
  return it == h.literals.end() ? std::vector<std::string>{"<missing>"} : it->second;
}

TEST(Generate, SensorCurvesAreFloatArraysOfTheirKnots) {
  HadynetModel m = synthetic_model(true);
  const trainer::SensorCurve curve{"fc1", {-0.5, 0.25, 2.0}, {-0.4, 0.3, 1.7}};
  m.sensor.curves = {curve};
  const auto& y = m.layout.y_names;
  const std::string channel = std::to_string(std::find(y.begin(), y.end(), "fc1") - y.begin());
  std::vector<std::string> level, reading;
  for (std::size_t k = 0; k < curve.level.size(); ++k) {
    level.push_back(float_literal(static_cast<float>(curve.level[k])));
    reading.push_back(float_literal(static_cast<float>(curve.reading[k])));
  }
  for (const Numeric n : {Numeric::kQ15, Numeric::kF32}) {  // physical floats in both numerics
    CodegenOptions o;
    o.numeric = n;
    const GeneratedHeader h = generate(m, kIdentity, o);
    EXPECT_EQ(literal(h, "kCurveCount"), std::vector<std::string>{"1"});
    EXPECT_EQ(literal(h, "kCurveKnots"), std::vector<std::string>{"3"});
    EXPECT_EQ(literal(h, "kCurveChannel"), std::vector<std::string>{channel});
    EXPECT_EQ(literal(h, "kCurveLevel"), level);
    EXPECT_EQ(literal(h, "kCurveReading"), reading);
    EXPECT_TRUE(contains(h.text, "static constexpr float kCurveLevel[3] = {")) << h.text;
    EXPECT_TRUE(contains(h.text, "measured y_c = clip(g_c(y'_c) + sum gain y'_source + rate D_c)"));
    EXPECT_TRUE(contains(h.text, "// fc1 reads g(fc1), g through -0.5 -> -0.4, 0.25 -> 0.3, 2 -> 1.7"));
  }
  // Without a curve: count 0 and one unused identity segment.
  const GeneratedHeader none = generate_q15(synthetic_model(true));
  EXPECT_EQ(literal(none, "kCurveCount"), std::vector<std::string>{"0"});
  EXPECT_EQ(literal(none, "kCurveKnots"), std::vector<std::string>{"2"});
  EXPECT_EQ(literal(none, "kCurveChannel"), std::vector<std::string>{"0"});
  EXPECT_EQ(literal(none, "kCurveLevel"), (std::vector<std::string>{"0.0f", "1.0f"}));
  EXPECT_EQ(literal(none, "kCurveReading"), (std::vector<std::string>{"0.0f", "1.0f"}));
}

// The knots are model data (a model image carries them); the curves'
// count, knot count and channels are shape (docs/model-update.md).
TEST(Generate, SensorCurveKnotsAreDataTheirChannelsShape) {
  HadynetModel m = synthetic_model(true);
  m.sensor.curves = {{"fc1", {0.0, 1.0, 2.0}, {0.0, 1.2, 2.1}}};
  const std::uint64_t shape = generate_q15(m).shape_id;
  HadynetModel other_knots = m;
  other_knots.sensor.curves[0].reading = {0.1, 1.0, 2.5};
  other_knots.sensor.curves[0].level = {-0.2, 0.8, 2.2};
  EXPECT_EQ(generate_q15(other_knots).shape_id, shape);
  HadynetModel other_channel = m;
  other_channel.sensor.curves[0].channel = "fc0";
  EXPECT_NE(generate_q15(other_channel).shape_id, shape);
  HadynetModel more_knots = m;
  more_knots.sensor.curves[0] = {"fc1", {0.0, 1.0, 2.0, 3.0}, {0.0, 1.2, 2.1, 3.0}};
  EXPECT_NE(generate_q15(more_knots).shape_id, shape);
  EXPECT_NE(generate_q15(synthetic_model(true)).shape_id, shape);
}

// Curves with fewer knots than the model's most get more on their last
// segment's extension (the firmware has one knot count): g is unchanged.
TEST(Generate, SensorCurvesWithFewerKnotsArePaddedOnTheirEndSegment) {
  HadynetModel m = synthetic_model(true);
  m.sensor.curves = {{"fc0", {0.0, 1.0}, {0.0, 1.5}}, {"fc1", {0.0, 1.0, 2.0}, {0.0, 1.2, 2.1}}};
  const SensorArrays a = sensor_arrays(m, false, 0);
  EXPECT_EQ(a.curve_knots, 3);
  EXPECT_EQ(a.curve_level, (std::vector<std::string>{"0.0f", "1.0f", "2.0f", "0.0f", "1.0f", "2.0f"}));
  EXPECT_EQ(a.curve_reading, (std::vector<std::string>{"0.0f", "1.5f", "3.0f", "0.0f", "1.20000005f", "2.0999999f"}));
}

// kClipRailModel is the rail on the network's channel (frame_rail): the
// type's extreme, which never clips, where cross-talk offsets the channel.
TEST(Generate, ACrosstalkTargetHasNoFrameRail) {
  HadynetModel m = synthetic_model(true);
  m.sensor.crosstalk = {{"fc0", "fc1", 0.25}};
  m.sensor.clips = {{"fc0", -1, 0.0}, {"fc0", 1, 50.0}, {"fc1", -1, 0.0}};
  const auto& y = m.layout.y_names;
  const auto r = std::find(y.begin(), y.end(), "fc1") - y.begin();
  const SensorArrays q15 = sensor_arrays(m, true, 12);
  ASSERT_EQ(q15.clip_rail_model.size(), 3u);
  EXPECT_EQ(q15.clip_rail_model[0], "-32768");
  EXPECT_EQ(q15.clip_rail_model[1], "32767");
  const double fc1_rail = (0.0 - m.norm.y.mean(r)) / m.norm.y.std(r);
  EXPECT_EQ(q15.clip_rail_model[2], std::to_string(std::clamp<std::int64_t>(to_fixed(fc1_rail, 12), -32768, 32767)));
  const SensorArrays f32 = sensor_arrays(m, false, 0);
  EXPECT_EQ(f32.clip_rail_model[0], float_literal(std::numeric_limits<float>::lowest()));
  EXPECT_EQ(f32.clip_rail_model[1], float_literal(std::numeric_limits<float>::max()));
  EXPECT_EQ(f32.clip_rail_model[2], float_literal(static_cast<float>(fc1_rail)));
  EXPECT_EQ(f32.clip_rail, (std::vector<std::string>{"0.0f", "50.0f", "0.0f"}));  // the measured clip keeps every rail
}

TEST(Rejects, SensorCurveKnotsThatAreEqualInFloat) {
  HadynetModel m = synthetic_model(true);
  // Strictly increasing in double (the trainer's check passes), one float apart at most.
  m.sensor.curves = {{"fc1", {0.0, 1.0, 1.0 + 1e-12}, {0.0, 1.0, 2.0}}};
  expect_unsupported(m, {}, "sensor curve of fc1: knots 1 and 2 are equal in float");
  // A curve the trainer rejects (not increasing) is rejected as the model's inconsistency.
  m.sensor.curves = {{"fc1", {0.0, 1.0, 2.0}, {0.0, 2.0, 1.0}}};
  expect_unsupported(m, {}, "not strictly increasing");
}

}  // namespace
}  // namespace hadynet::codegen
