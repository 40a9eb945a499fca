// Golden generated headers of a tiny model (test/codegen/golden/): codegen's
// whole output for synthetic_model(true), q15 and f32, checked in and compared
// byte for byte. Any change to the text codegen writes (a value, a format, a
// comment, the order of members) fails here and shows up in review as a diff
// of the golden file. After an intended change, regenerate them with
//   HADYNET_UPDATE_GOLDEN=1 build/release/test/codegen/codegen_golden_tests
// and commit the new files with the change that explains them.
//
// This test links portable code only (codegen, the model-file and
// deploy-math libraries; no -march=native), as hadynet-codegen does: the
// golden bytes are what every x86-64 machine must write, so a run on another
// machine checks that codegen's output does not depend on the CPU.
//
// The same golden headers are compiled into this test (they must satisfy
// firmware/core/model_contract.h: each ends in a static_assert of it) and
// their dimensions are checked against the model they came from.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "codegen/codegen.h"
#include "test/codegen/golden/hadynet_model_f32.h"
#include "test/codegen/golden/hadynet_model_q15.h"
#include "test/codegen/synthetic_model.h"

namespace hadynet::codegen {
namespace {

const ModelIdentity kGoldenIdentity{"tiny.safetensors", 0x0123456789abcdefULL};

std::string golden_path(Numeric numeric) {
  return std::string(HADYNET_GOLDEN_DIR) + "/" + header_file_name(numeric);
}

// The first line where `a` and `b` differ, for the failure message.
std::string first_difference(const std::string& a, const std::string& b) {
  std::istringstream sa(a), sb(b);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool ga = static_cast<bool>(std::getline(sa, la));
    const bool gb = static_cast<bool>(std::getline(sb, lb));
    if (!ga && !gb) return "identical";
    if (!ga || !gb || la != lb) {
      return "line " + std::to_string(line) + ":\n  golden:    " + (ga ? la : "<end>") + "\n  generated: " +
             (gb ? lb : "<end>");
    }
  }
}

void check_golden(Numeric numeric) {
  CodegenOptions options;
  options.numeric = numeric;
  options.ns = std::string("hadynet::golden_") + numeric_name(numeric);
  const GeneratedHeader header = generate(test::synthetic_model(true), kGoldenIdentity, options);
  const std::string path = golden_path(numeric);
  if (std::getenv("HADYNET_UPDATE_GOLDEN") != nullptr) {
    std::ofstream(path, std::ios::binary) << header.text;
    GTEST_SKIP() << "rewrote " << path;
  }
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in) << path << " is missing (HADYNET_UPDATE_GOLDEN=1 writes it)";
  const std::string golden{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_TRUE(golden == header.text) << path << " differs from what codegen writes now, first at "
                                     << first_difference(golden, header.text);
}

TEST(GoldenHeader, Q15IsWhatCodegenWrites) { check_golden(Numeric::kQ15); }
TEST(GoldenHeader, F32IsWhatCodegenWrites) { check_golden(Numeric::kF32); }

template <class M>
void expect_dims_of_the_model() {
  const trainer::HadynetModel m = test::synthetic_model(true);
  EXPECT_EQ(M::kX, m.params.dims.x);
  EXPECT_EQ(M::kU, m.params.dims.u);
  EXPECT_EQ(M::kY, m.params.dims.y);
  EXPECT_EQ(M::kPb, m.params.dims.pb);
  EXPECT_EQ(M::kHidden, m.params.dims.hidden);
  EXPECT_EQ(M::kStates, m.params.dims.states);
  EXPECT_EQ(M::kPeriodUs, 200000u);
  EXPECT_TRUE(M::kHasDetection);
}

TEST(GoldenHeader, CompilesAgainstTheContractWithTheModelsDimensions) {
  expect_dims_of_the_model<golden_q15::Model>();
  expect_dims_of_the_model<golden_f32::Model>();
}

}  // namespace
}  // namespace hadynet::codegen
