// The q15 kernels' bit-exactness test (kernel_exactness.h) as a test image
// for mps2-an386: the build's Cortex-M4 DSP kernels under QEMU, run by CTest
// (test/boards/CMakeLists.txt). Output on UART0; the exit code (semihosting)
// is the number of failures, capped at 100.
#include <string_view>

#include "boards/board.h"
#include "test/boards/kernel_exactness.h"

int main() {
  hadynet::board::init();
  const int failures = hadynet::test::run_kernel_exactness([](std::string_view text) {
    hadynet::board::uart_write(reinterpret_cast<const unsigned char*>(text.data()), text.size());
  });
  return failures > 100 ? 100 : failures;
}
