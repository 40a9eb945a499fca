#include "host-sim/model_image/signing_key.h"

#include <sodium.h>

#include <cstring>
#include <fstream>
#include <sstream>

#include "datalog/atomic_file.h"

namespace hadynet::host {

namespace {

constexpr const char* kDevelopmentMark = "# DEVELOPMENT KEY";

void init_sodium() {
  if (sodium_init() < 0) throw std::runtime_error("libsodium could not be initialised");
}

// The hex digits after `keyword ` on the first non-comment line of `path`.
std::string key_field(const std::filesystem::path& path, const std::string& keyword, std::size_t digits,
                      bool* development) {
  std::ifstream in(path);
  if (!in) throw KeyFileError(path.string() + ": cannot be read");
  std::string line;
  int number = 0;
  if (development != nullptr) *development = false;
  while (std::getline(in, line)) {
    ++number;
    if (line.rfind(kDevelopmentMark, 0) == 0 && development != nullptr) *development = true;
    if (line.empty() || line[0] == '#') continue;
    const std::string where = path.string() + ":" + std::to_string(number) + ": ";
    if (line.rfind(keyword + " ", 0) != 0) throw KeyFileError(where + "expected '" + keyword + " <hex>'");
    const std::string value = line.substr(keyword.size() + 1);
    if (value.size() != digits || value.find_first_not_of("0123456789abcdef") != std::string::npos) {
      throw KeyFileError(where + "expected " + std::to_string(digits) + " lower-case hex digits");
    }
    return value;
  }
  throw KeyFileError(path.string() + ": no '" + keyword + " <hex>' line");
}

template <std::size_t N>
std::array<std::uint8_t, N> from_hex(const std::string& digits) {
  std::array<std::uint8_t, N> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = static_cast<std::uint8_t>(std::stoi(digits.substr(2 * i, 2), nullptr, 16));
  return out;
}

std::string comments(const SigningKey& key, bool secret) {
  std::string s;
  if (key.development) {
    s += std::string(kDevelopmentMark) + ": for tests and development only. Its secret half is public,\n";
    s += "# so anyone can sign images a firmware built with it accepts. Make your own: hadynet keygen.\n";
  }
  s += secret ? "# HADYNET model-image signing key (Ed25519, libsodium secret key: seed || public key).\n"
                "# Keep it private: whoever holds it can update the models of every hand built with\n"
                "# its public half (the .pub file next to it).\n"
              : "# HADYNET model-image public key (Ed25519): build the firmware with it\n"
                "# (-DHADYNET_MODEL_PUBLIC_KEY=<this file>); it accepts images signed by its secret half.\n";
  return s;
}

}  // namespace

std::string hex(std::span<const std::uint8_t> bytes) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string s;
  for (const std::uint8_t b : bytes) {
    s += kDigits[b >> 4];
    s += kDigits[b & 15];
  }
  return s;
}

SigningKey generate_signing_key(bool development) {
  init_sodium();
  SigningKey key;
  crypto_sign_keypair(key.public_key.data(), key.secret.data());
  key.development = development;
  return key;
}

void write_signing_key(const std::filesystem::path& path, const SigningKey& key) {
  // The secret key is created mode 0600 before its bytes are written, and
  // never replaces an existing file.
  try {
    datalog::write_file_atomically(path, comments(key, true) + "secret " + hex(key.secret) + "\n",
                                   {.mode = 0600, .replace = false});
  } catch (const datalog::AtomicWriteError& e) {
    if (std::filesystem::exists(path)) throw KeyFileError(path.string() + ": exists; not overwriting a key");
    throw KeyFileError(e.what());
  }
  std::filesystem::path pub = path;
  pub += ".pub";
  datalog::write_file_atomically(pub, comments(key, false) + "public " + hex(key.public_key) + "\n");
}

SigningKey read_signing_key(const std::filesystem::path& path) {
  init_sodium();
  SigningKey key;
  key.secret = from_hex<64>(key_field(path, "secret", 128, &key.development));
  // libsodium's secret key is seed || public key: the public half must be
  // the one the seed gives.
  std::array<std::uint8_t, 64> again{};
  crypto_sign_seed_keypair(key.public_key.data(), again.data(), key.secret.data());
  if (std::memcmp(key.public_key.data(), key.secret.data() + 32, 32) != 0)
    throw KeyFileError(path.string() + ": the secret key's two halves do not belong together");
  sodium_memzero(again.data(), again.size());
  return key;
}

PublicKey read_public_key(const std::filesystem::path& path, bool* development) {
  std::ifstream in(path);
  std::string first;
  bool secret = false;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    secret = line.rfind("secret ", 0) == 0;
    break;
  }
  if (secret) {
    const SigningKey key = read_signing_key(path);
    if (development != nullptr) *development = key.development;
    return key.public_key;
  }
  return from_hex<32>(key_field(path, "public", 64, development));
}

std::array<std::uint8_t, 64> sign(const SigningKey& key, std::span<const std::uint8_t> message) {
  init_sodium();
  std::array<std::uint8_t, 64> sig{};
  crypto_sign_detached(sig.data(), nullptr, message.data(), message.size(), key.secret.data());
  return sig;
}

std::array<std::uint8_t, 32> sha256(std::span<const std::uint8_t> bytes) {
  init_sodium();
  std::array<std::uint8_t, 32> h{};
  crypto_hash_sha256(h.data(), bytes.data(), bytes.size());
  return h;
}

}  // namespace hadynet::host
