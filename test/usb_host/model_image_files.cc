#include "test/usb_host/model_image_files.h"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iterator>

#include "test/usb_host/child_process.h"

#if !defined(HADYNET_CLI_EXECUTABLE) || !defined(HADYNET_MODEL_FILE) || !defined(HADYNET_DEVELOPMENT_KEY_FILE)
#error "the build defines HADYNET_CLI_EXECUTABLE, HADYNET_MODEL_FILE and HADYNET_DEVELOPMENT_KEY_FILE"
#endif

namespace hadynet::usb::host_testing {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// Tolerance: model-image takes ~50 ms, keygen less; 30 s only catches a hang.
constexpr auto kToolTimeout = 30s;

fs::path development_key_file() { return HADYNET_DEVELOPMENT_KEY_FILE; }

fs::path make_model_image(UsbTestbed& bus, const fs::path& dir, std::uint32_t sequence, const fs::path& key) {
  const fs::path out = dir / ("model-" + std::to_string(sequence) + "-" + key.stem().string() + ".img");
  const ChildResult r = run_child(bus,
                                  {HADYNET_CLI_EXECUTABLE, "model-image", HADYNET_MODEL_FILE, "--key", key.string(),
                                   "--sequence", std::to_string(sequence), "--out", out.string()},
                                  kToolTimeout);
  if (!r.started || r.exit_code != 0) {
    ADD_FAILURE() << "hadynet model-image: " << r.describe();
    return {};
  }
  return out;
}

fs::path make_other_key(UsbTestbed& bus, const fs::path& dir) {
  const fs::path key = dir / "other.key";
  const ChildResult r = run_child(bus, {HADYNET_CLI_EXECUTABLE, "keygen", "--out", key.string()}, kToolTimeout);
  if (!r.started || r.exit_code != 0) {
    ADD_FAILURE() << "hadynet keygen: " << r.describe();
    return {};
  }
  return key;
}

std::vector<std::uint8_t> read_file(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(f), {});
}

}  // namespace hadynet::usb::host_testing
