// The link fuzzer's seed corpus (fuzz/corpus/link) through the fuzzer's own
// harness and oracle (fuzz/link_fuzz_harness.h), built with the regular
// compiler: the seeds stay meaningful (valid sessions are executed, each
// malformed seed draws error replies) and the oracle holds on them even
// where clang is not installed. An oracle violation aborts the test binary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "fuzz/link_fuzz_harness.h"

namespace hadynet::link {
namespace {

// The checked-in seeds were written for the default model (the hand: y 27,
// u 8, PB 8); with another HADYNET_MODEL their sensor frames have the wrong
// size, so only the oracle is checked (regenerate them with make_link_corpus).
constexpr bool kCorpusShapes =
    fuzz::FuzzModel::kY == 27 && fuzz::FuzzModel::kU == 8 && fuzz::FuzzModel::kPb == 8 && fuzz::FuzzModel::kStates >= 2;

std::vector<std::filesystem::path> seeds() {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(HADYNET_LINK_CORPUS_DIR)) {
    if (e.is_regular_file()) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(LinkFuzzCorpus, SeedsPassTheOracleAndDoWhatTheirNamesSay) {
  const auto files = seeds();
  ASSERT_GE(files.size(), 10u) << "seed corpus missing: " << HADYNET_LINK_CORPUS_DIR;
  for (const auto& path : files) {
    SCOPED_TRACE(path.string());
    std::ifstream in(path, std::ios::binary);
    const std::vector<std::uint8_t> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto harness = std::make_unique<fuzz::LinkFuzzHarness>();
    harness->run(data.data(), data.size());
    const std::string name = path.filename().string();
    EXPECT_GT(harness->replies(), 0u);
    if (!kCorpusShapes) continue;  // the oracle held; the seeds' intent needs their model's shapes
    if (name.rfind("valid_", 0) == 0) {
      EXPECT_EQ(harness->executed(), harness->replies()) << "a valid seed drew an error reply";
    } else {
      EXPECT_LT(harness->executed(), harness->replies()) << "a malformed seed drew no error reply";
    }
  }
}

}  // namespace
}  // namespace hadynet::link
