#include "tools/usb/model_image_file.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string_view>

#ifndef HADYNET_DEVELOPMENT_PUBLIC_KEY_HEX
#error "the build defines HADYNET_DEVELOPMENT_PUBLIC_KEY_HEX (64 hex digits of keys/development.key.pub)"
#endif

namespace hadynet::tools::usb {

namespace mu = model_update;

ModelImageFile check_model_image_bytes(std::vector<std::uint8_t> bytes, const std::string& name) {
  if (bytes.size() < mu::kImageHeaderSize) {
    throw ModelImageFileError(name + ": " + std::to_string(bytes.size()) +
                              " bytes, shorter than a model image's 256-byte header (hadynet model-image makes "
                              "images)");
  }
  ModelImageFile f;
  const mu::HeaderFormat format = mu::decode_model_image_header(
      std::span<const std::uint8_t, mu::kImageHeaderSize>(bytes.data(), mu::kImageHeaderSize), f.header);
  if (format != mu::HeaderFormat::kWellFormed) {
    throw ModelImageFileError(name + ": not a model image: " + mu::header_format_text(format) +
                              " (hadynet model-image makes images)");
  }
  const std::uint64_t expected = mu::kImageHeaderSize + static_cast<std::uint64_t>(f.header.payload_length);
  if (bytes.size() != expected) {
    throw ModelImageFileError(name + ": " + std::to_string(bytes.size()) + " bytes, but its header says 256 + " +
                              std::to_string(f.header.payload_length) + " = " + std::to_string(expected) +
                              " (a truncated or extended file)");
  }
  f.bytes = std::move(bytes);
  return f;
}

ModelImageFile load_model_image_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ModelImageFileError(path.string() + ": cannot open");
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw ModelImageFileError(path.string() + ": read error");
  return check_model_image_bytes(std::move(bytes), path.string());
}

const std::array<std::uint8_t, mu::kPublicKeyBytes>& development_public_key() {
  static const std::array<std::uint8_t, mu::kPublicKeyBytes> key = [] {
    constexpr std::string_view hex = HADYNET_DEVELOPMENT_PUBLIC_KEY_HEX;
    static_assert(hex.size() == 2 * mu::kPublicKeyBytes, "64 hex digits");
    const auto digit = [](char c) {
      return static_cast<std::uint8_t>(c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10);
    };
    std::array<std::uint8_t, mu::kPublicKeyBytes> k{};
    for (std::size_t i = 0; i < k.size(); ++i) {
      k[i] = static_cast<std::uint8_t>(digit(hex[2 * i]) << 4 | digit(hex[2 * i + 1]));
    }
    return k;
  }();
  return key;
}

bool is_development_key(std::span<const std::uint8_t, mu::kPublicKeyBytes> key) {
  return std::equal(key.begin(), key.end(), development_public_key().begin());
}

}  // namespace hadynet::tools::usb
