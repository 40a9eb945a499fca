// libFuzzer target for the dataset manifest reader
// (datalog/dataset_manifest.h): any bytes give a manifest whose every entry
// is a relative path inside the dataset folder, or a LogError naming the
// field. Another exception (a JSON library's own), a crash or a sanitizer
// report is a finding.
//   build/release/fuzz/manifest_fuzzer -max_len=4096 WORKDIR fuzz/corpus/manifest
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "datalog/dataset_manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hadynet::datalog;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const DatasetManifest m = parse_dataset_manifest(text, "manifest.json");
    if (m.logs.size() > kMaxManifestLogs) std::abort();
    for (const auto& log : m.logs) {
      if (log.file.empty() || log.file.is_absolute()) std::abort();
      for (const auto& part : log.file)
        if (part == "..") std::abort();
    }
  } catch (const LogError& e) {
    if (e.what()[0] == '\0') std::abort();
  }
  return 0;
}
