#include "firmware/crypto/field25519.h"

namespace hadynet::crypto::gf25519::internal {

Element add_out_of_line(const Element& a, const Element& b) noexcept { return add_impl(a, b); }
Element sub_out_of_line(const Element& a, const Element& b) noexcept { return sub_impl(a, b); }
Element mul_out_of_line(const Element& a, const Element& b) noexcept { return mul_impl(a, b); }
Element square_out_of_line(const Element& a) noexcept { return square_impl(a); }

}  // namespace hadynet::crypto::gf25519::internal
