// The q15 kernels' bit-exactness test (kernel_exactness.h) on the host: the
// build's reference kernels against fixed_point.h and activation.h, the same
// cases the QEMU test runs on the DSP kernels.
#include <cstdio>
#include <string_view>

#include "test/boards/kernel_exactness.h"

int main() {
  const int failures = hadynet::test::run_kernel_exactness(
      [](std::string_view text) { std::fwrite(text.data(), 1, text.size(), stdout); });
  return failures == 0 ? 0 : 1;
}
