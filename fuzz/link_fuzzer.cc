// libFuzzer target for the link: stream decoder, frame parser and
// dispatcher, driving a fresh q15 runtime per input, with the robustness
// contract as the oracle (link_fuzz_harness.h; input format:
// link_fuzz_input.h). Built with clang -fsanitize=fuzzer,address,undefined
// (fuzz/CMakeLists.txt); CTest runs it briefly on the seed corpus
// fuzz/corpus/link. By hand:
//   build/release/fuzz/link_fuzzer -max_len=2048 WORKDIR fuzz/corpus/link
// (new inputs go to the first directory, so keep the seeds second).
#include <cstddef>
#include <cstdint>
#include <memory>

#include "fuzz/link_fuzz_harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto harness = std::make_unique<hadynet::link::fuzz::LinkFuzzHarness>();
  harness->run(data, size);
  return 0;
}
