// Writes the USB fuzzer's seed inputs (usb_fuzz_seeds.h) into a directory.
//   usb_make_corpus DIR
#include <cstdint>
#include <cstdio>
#include <string>

#include "fuzz/usb_fuzz_seeds.h"

namespace {

bool write(const std::string& path, const std::vector<std::uint8_t>& b) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(b.data(), 1, b.size(), f) == b.size();
  return std::fclose(f) == 0 && ok;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: usb_make_corpus DIR\n");
    return 2;
  }
  for (const auto& [name, input] : hadynet::usb::fuzz::seeds::all()) {
    const std::string path = std::string(argv[1]) + "/" + name;
    if (!write(path, input)) {
      std::fprintf(stderr, "usb_make_corpus: cannot write %s\n", path.c_str());
      return 1;
    }
  }
  return 0;
}
