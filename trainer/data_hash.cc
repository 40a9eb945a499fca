#include "trainer/data_hash.h"

#include <sodium.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace hadynet::trainer {

std::string data_hash(const std::vector<std::string>& paths) {
  if (sodium_init() < 0) throw std::runtime_error("libsodium failed to initialise");
  crypto_hash_sha256_state state;
  crypto_hash_sha256_init(&state);
  const auto mix = [&state](const char* data, std::size_t n) {
    crypto_hash_sha256_update(&state, reinterpret_cast<const unsigned char*>(data), n);
  };
  std::vector<char> buffer(1 << 16);
  for (const std::string& path : paths) {
    const std::string name = std::filesystem::path(path).filename().string();
    mix(name.data(), name.size() + 1);  // with the terminating 0 as a separator
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path + ": cannot read");
    while (in) {
      in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
      mix(buffer.data(), static_cast<std::size_t>(in.gcount()));
    }
  }
  unsigned char digest[crypto_hash_sha256_BYTES];
  crypto_hash_sha256_final(&state, digest);
  char hex[2 * crypto_hash_sha256_BYTES + 1];
  sodium_bin2hex(hex, sizeof hex, digest, sizeof digest);
  return hex;
}

}  // namespace hadynet::trainer
