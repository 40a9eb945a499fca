// FNV-1a 64 (offset basis 0xcbf29ce484222325, prime 0x100000001b3): the
// content hash of the host tools. It identifies a model file to the firmware
// (codegen's kModelHash, the link's INFO reply, `hadynet devices`) and a
// dataset to a model's provenance (trainer::content_hash). It detects
// changed content; it is not a cryptographic digest (model images are
// authenticated elsewhere).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace hadynet::datalog {

class Fnv1a64 {
 public:
  // Feeds `bytes` (any number of calls; the hash of the concatenation).
  void update(std::string_view bytes) noexcept {
    for (const char c : bytes) {
      hash_ ^= static_cast<unsigned char>(c);
      hash_ *= 0x100000001b3ULL;
    }
  }
  std::uint64_t value() const noexcept { return hash_; }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

inline std::uint64_t fnv1a64(std::string_view bytes) noexcept {
  Fnv1a64 h;
  h.update(bytes);
  return h.value();
}

}  // namespace hadynet::datalog
