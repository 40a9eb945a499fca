#include "firmware/crypto/ed25519_verify.h"

#include "firmware/crypto/edwards25519.h"
#include "firmware/crypto/field25519.h"
#include "firmware/crypto/scalar25519.h"
#include "firmware/crypto/sha512.h"

namespace hadynet::crypto {
namespace {

// k = SHA-512(R || A || M) mod L (RFC 8032 §5.1.7 step 2).
scalar25519::Scalar challenge(std::span<const std::uint8_t, 32> r, std::span<const std::uint8_t, 32> a,
                              std::span<const std::uint8_t> message) noexcept {
  Sha512 hash;
  hash.update(r);
  hash.update(a);
  hash.update(message);
  const std::array<std::uint8_t, kSha512Bytes> digest = hash.finish();
  return scalar25519::reduce_wide(digest);
}

}  // namespace

bool ed25519_verify(std::span<const std::uint8_t, kEd25519SignatureBytes> signature,
                    std::span<const std::uint8_t> message,
                    std::span<const std::uint8_t, kEd25519PublicKeyBytes> public_key) noexcept {
  const std::span<const std::uint8_t, 32> r = signature.first<32>();

  // Rule 1: S < L.
  scalar25519::Scalar s;
  if (!scalar25519::from_canonical_bytes(s, signature.last<32>())) return false;
  // Rule 2: R not of small order.
  if (edwards25519::has_small_order_y(r)) return false;
  // Rule 3: A canonical, not of small order, a curve point.
  if (!gf25519::is_canonical(public_key) || edwards25519::has_small_order_y(public_key)) return false;
  const scalar25519::Scalar k = challenge(r, public_key, message);
  edwards25519::Extended a;
  if (!edwards25519::decode(a, public_key)) return false;

  // Rule 4: encode([S]B + [k](-A)) == R.
  edwards25519::PointMultiples minus_a_multiples;
  edwards25519::fill_odd_multiples(minus_a_multiples, edwards25519::negate(a));
  const edwards25519::Projective check = edwards25519::double_scalar_mul_base(s, k, minus_a_multiples);
  const std::array<std::uint8_t, 32> encoded = edwards25519::encode(check);
  for (std::size_t i = 0; i < 32; ++i) {
    if (encoded[i] != r[i]) return false;
  }
  return true;
}

}  // namespace hadynet::crypto
