// The model image writer against the firmware's compiled-in model: the
// built-in model's image carries exactly the bytes of kCompiledTensors (so a
// runtime reading it from a slot computes what the compiled-in one does),
// another shape or too little range is refused, and the header is signed
// over what the device checks. Tolerances: none (bytes and checksums equal).
#include <gtest/gtest.h>
#include <sodium.h>

#include <cstring>
#include <memory>
#include <string>

#include "codegen/codegen.h"
#include "codegen/unsupported_model.h"
#include "firmware/app/runtime_checksum.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "host-sim/model_image/model_image_writer.h"

namespace {

using Q = hadynet::model_q15::Model;
using F = hadynet::model_f32::Model;
using hadynet::codegen::CodegenOptions;
using hadynet::codegen::GeneratedHeader;
using hadynet::codegen::LoadedModel;
using hadynet::firmware::ModelTensors;

const LoadedModel& built_in() {
  static const LoadedModel m = hadynet::codegen::load_model_file(HADYNET_MODEL_PATH);
  return m;
}

// The options the build generated its headers with (only --control-commands
// is understood; other build options skip the tests that need them).
bool build_options(CodegenOptions& o) {
  const std::string text = HADYNET_CODEGEN_OPTIONS;
  if (text.empty()) return true;
  const std::string flag = "--control-commands ";
  if (text.rfind(flag, 0) != 0 || text.find(' ', flag.size()) != std::string::npos) return false;
  o.control.commands.emplace();
  const std::string list = text.substr(flag.size());
  for (std::size_t pos = 0; pos <= list.size();) {
    const std::size_t comma = std::min(list.find(',', pos), list.size());
    o.control.commands->push_back(list.substr(pos, comma - pos));
    pos = comma + 1;
  }
  return true;
}

template <class M>
GeneratedHeader header_for(const hadynet::trainer::HadynetModel& model, CodegenOptions o) {
  o.numeric = M::kNumeric;
  if (M::kNumeric == hadynet::firmware::Numeric::kQ15) o.target_formats = hadynet::host::firmware_formats<M>();
  return hadynet::codegen::generate(model, built_in().identity, o);
}

template <class M>
void expect_compiled_bytes() {
  CodegenOptions o;
  if (!build_options(o)) GTEST_SKIP() << "the build's HADYNET_CODEGEN_OPTIONS are more than --control-commands";
  const GeneratedHeader h = header_for<M>(built_in().model, o);
  EXPECT_EQ(h.shape_id, M::kShapeId);
  const auto tensors = hadynet::host::tensors_of<M>(h);
  ASSERT_EQ(0, std::memcmp(tensors.get(), &hadynet::firmware::kCompiledTensors<M>, sizeof(ModelTensors<M>)))
      << "the image's tensors differ from the compiled-in ones";
  auto compiled = std::make_unique<hadynet::firmware::HadynetRuntime<M>>();
  EXPECT_EQ(hadynet::host::self_test_checksum<M>(*tensors), hadynet::app::runtime_checksum(*compiled));
}

TEST(ModelImage, BuiltInModelQ15IsTheCompiledInTensorsBitForBit) { expect_compiled_bytes<Q>(); }
TEST(ModelImage, BuiltInModelF32IsTheCompiledInTensorsBitForBit) { expect_compiled_bytes<F>(); }

TEST(ModelImage, AnotherShapeIsRefusedNamingWhatDiffers) {
  CodegenOptions o;
  ASSERT_TRUE(build_options(o));
  o.control.horizon = 6;  // the firmware's is 8
  const GeneratedHeader h = header_for<Q>(built_in().model, o);
  EXPECT_NE(h.shape_id, Q::kShapeId);
  try {
    (void)hadynet::host::tensors_of<Q>(h);
    FAIL() << "another shape was accepted";
  } catch (const hadynet::host::ModelImageError& e) {
    EXPECT_NE(std::string(e.what()).find("kControlHorizon 6 (firmware 8)"), std::string::npos) << e.what();
  }
}

TEST(ModelImage, TargetFormatWithLessRangeIsRefused) {
  CodegenOptions o;
  ASSERT_TRUE(build_options(o));
  o.target_formats = hadynet::host::firmware_formats<Q>();
  (*o.target_formats)[1] += 1;  // kFracH: half the range the model needs
  try {
    (void)hadynet::codegen::generate(built_in().model, built_in().identity, o);
    FAIL() << "a format with less range was accepted";
  } catch (const hadynet::codegen::UnsupportedModel& e) {
    EXPECT_NE(std::string(e.what()).find("kFracH"), std::string::npos) << e.what();
  }
}

TEST(ModelImage, RetrainedWeightsGiveOtherTensorsAndChecksumInTheSameShape) {
  CodegenOptions o;
  ASSERT_TRUE(build_options(o));
  hadynet::trainer::HadynetModel changed = built_in().model;
  // A model of the same shape with other data (weights whose largest
  // magnitude is unchanged, so the stored value ranges still hold).
  changed.params.dec_bias.array() += 0.01f;
  changed.params.pb.row(0).swap(changed.params.pb.row(1));
  const GeneratedHeader h = header_for<Q>(changed, o);
  ASSERT_EQ(h.shape_id, Q::kShapeId);
  const auto tensors = hadynet::host::tensors_of<Q>(h);
  EXPECT_NE(0, std::memcmp(tensors.get(), &hadynet::firmware::kCompiledTensors<Q>, sizeof(ModelTensors<Q>)));
  auto compiled = std::make_unique<hadynet::firmware::HadynetRuntime<Q>>();
  EXPECT_NE(hadynet::host::self_test_checksum<Q>(*tensors), hadynet::app::runtime_checksum(*compiled));
}

TEST(ModelImage, HeaderIsSignedOverWhatTheDeviceChecks) {
  CodegenOptions o;
  ASSERT_TRUE(build_options(o));
  const GeneratedHeader h = header_for<Q>(built_in().model, o);
  const hadynet::host::SigningKey key = hadynet::host::generate_signing_key(false);
  const hadynet::host::ModelImage image =
      hadynet::host::make_model_image<Q>(h, key, {7, false});
  namespace mu = hadynet::model_update;
  ASSERT_EQ(image.bytes.size(), mu::kImageHeaderSize + sizeof(ModelTensors<Q>));
  mu::ModelImageHeader decoded;
  ASSERT_EQ(mu::decode_model_image_header(std::span<const std::uint8_t, mu::kImageHeaderSize>(
                                              image.bytes.data(), mu::kImageHeaderSize),
                                          decoded),
            mu::HeaderFormat::kWellFormed);
  EXPECT_EQ(decoded, image.header);
  EXPECT_EQ(decoded.sequence, 7u);
  EXPECT_EQ(decoded.shape_id, Q::kShapeId);
  EXPECT_EQ(decoded.payload_length, sizeof(ModelTensors<Q>));
  EXPECT_EQ(decoded.self_test_checksum, static_cast<std::uint32_t>(image.self_test_checksum));
  EXPECT_EQ(decoded.public_key, key.public_key);
  const std::span<const std::uint8_t> payload(image.bytes.data() + mu::kImageHeaderSize, decoded.payload_length);
  EXPECT_EQ(decoded.payload_sha256, hadynet::host::sha256(payload));
  EXPECT_EQ(0, crypto_sign_verify_detached(decoded.signature.data(), image.bytes.data(), mu::kSignedBytes,
                                           key.public_key.data()));
  // Any change of a signed byte breaks the signature.
  std::vector<std::uint8_t> tampered(image.bytes.begin(), image.bytes.begin() + mu::kSignedBytes);
  tampered[12] ^= 1;  // the sequence number
  EXPECT_NE(0, crypto_sign_verify_detached(decoded.signature.data(), tampered.data(), mu::kSignedBytes,
                                           key.public_key.data()));
}

}  // namespace

namespace {

// The self-test's frames follow the standardisation of the model under test,
// not the compiled-in one's: an image's checksum must be reproduced by any
// firmware of its shape, whichever model that firmware has compiled in.
// (With the compiled-in standardisation, frames would stay near it, |y| < 500.)
TEST(ModelImage, SelfTestFramesFollowTheImagesStandardisation) {
  auto shifted = std::make_unique<ModelTensors<Q>>(hadynet::firmware::kCompiledTensors<Q>);
  for (float& m : shifted->y_mean) m += 1000.0f;
  hadynet::app::SyntheticFrames<Q> frames(hadynet::app::kChecksumSeed, *shifted);
  hadynet::firmware::SensorFrame<Q> frame;
  for (int k = 0; k < 5; ++k) {
    frames.next(frame);
    for (int i = 0; i < Q::kY; ++i) EXPECT_GT(frame.y[i], 500.0f) << "frame " << k << " channel " << i;
  }
}

}  // namespace
