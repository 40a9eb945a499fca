// Signing key files: written, read back, refused when malformed (naming file
// and line), never overwritten; a development key says so.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "host-sim/model_image/signing_key.h"

namespace {

namespace fs = std::filesystem;
using hadynet::host::KeyFileError;

fs::path temp_dir() {
  const fs::path dir = fs::temp_directory_path() / ("hadynet_key_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

TEST(SigningKey, WrittenAndReadBack) {
  const fs::path dir = temp_dir();
  const fs::path path = dir / "owner.key";
  fs::remove(path);
  fs::remove(dir / "owner.key.pub");
  const auto key = hadynet::host::generate_signing_key(false);
  hadynet::host::write_signing_key(path, key);
  const auto back = hadynet::host::read_signing_key(path);
  EXPECT_EQ(back.secret, key.secret);
  EXPECT_EQ(back.public_key, key.public_key);
  EXPECT_FALSE(back.development);
  bool development = true;
  EXPECT_EQ(hadynet::host::read_public_key(dir / "owner.key.pub", &development), key.public_key);
  EXPECT_FALSE(development);
  EXPECT_EQ(fs::status(path).permissions() & fs::perms::others_read, fs::perms::none);
  EXPECT_THROW(hadynet::host::write_signing_key(path, key), KeyFileError);  // never overwritten
  fs::remove_all(dir);
}

TEST(SigningKey, DevelopmentKeySaysSo) {
  const fs::path dir = temp_dir();
  const fs::path path = dir / "dev.key";
  fs::remove(path);
  fs::remove(dir / "dev.key.pub");
  hadynet::host::write_signing_key(path, hadynet::host::generate_signing_key(true));
  EXPECT_TRUE(hadynet::host::read_signing_key(path).development);
  bool development = false;
  (void)hadynet::host::read_public_key(dir / "dev.key.pub", &development);
  EXPECT_TRUE(development);
  fs::remove_all(dir);
}

TEST(SigningKey, MalformedFilesNameFileAndLine) {
  const fs::path dir = temp_dir();
  const fs::path path = dir / "bad.key";
  std::ofstream(path) << "# comment\nsecret 12zz\n";
  try {
    (void)hadynet::host::read_signing_key(path);
    FAIL();
  } catch (const KeyFileError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.key:2:"), std::string::npos) << e.what();
  }
  // Halves that do not belong together (the public half of another key).
  const auto a = hadynet::host::generate_signing_key(false);
  const auto b = hadynet::host::generate_signing_key(false);
  std::array<std::uint8_t, 64> mixed = a.secret;
  std::copy(b.public_key.begin(), b.public_key.end(), mixed.begin() + 32);
  std::ofstream(path) << "secret " << hadynet::host::hex(mixed) << "\n";
  EXPECT_THROW((void)hadynet::host::read_signing_key(path), KeyFileError);
  EXPECT_THROW((void)hadynet::host::read_public_key(dir / "missing.pub"), KeyFileError);
  fs::remove_all(dir);
}

}  // namespace
