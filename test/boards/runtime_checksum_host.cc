// The q15 runtime checksum on the host (reference kernels): prints the line
// the benchmark image prints on the MCU (firmware/app/runtime_checksum.h),
//   checksum value=<16 hex digits>
// for the QEMU test that compares the two (test/boards/CMakeLists.txt).
#include <cstdio>

#include "firmware/app/runtime_checksum.h"
#include "firmware/core/hadynet_runtime.h"
#include "hadynet_model_q15.h"

namespace {
hadynet::firmware::HadynetRuntime<hadynet::model_q15::Model> g_runtime;  // too large for the stack
}

int main() {
  const auto value = static_cast<unsigned long long>(hadynet::app::runtime_checksum(g_runtime));
  std::printf("checksum value=%016llx\n", value);
  return 0;
}
