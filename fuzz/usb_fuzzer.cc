// libFuzzer target for the USB device stack (usb_fuzz_harness.h): arbitrary
// SETUP packets, data stages, tokens, bus resets and flash faults against a
// fresh composite device per input, invariants checked after every event.
// Built with clang -fsanitize=fuzzer,address,undefined (fuzz/CMakeLists.txt);
// CTest runs it briefly from seeds written by usb_make_corpus. By hand:
//   build/release/fuzz/usb_fuzzer -max_len=4096 WORKDIR build/release/fuzz/usb_corpus
#include <cstddef>
#include <cstdint>
#include <memory>

#include "fuzz/usb_fuzz_harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto harness = std::make_unique<hadynet::usb::fuzz::UsbFuzzHarness>();
  harness->run(data, size);
  return 0;
}
