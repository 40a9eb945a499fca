// Q3.12 -> Q0.15 tanh and sigmoid by table lookup and linear interpolation.
// See activation.h for the contract, formats and error bounds.
#include "firmware/core/activation.h"

#include <cstdint>

namespace hadynet::fixed {

namespace detail {

// kTanhQ15Table[i] = min(32767, floor(32768 * tanh(i / 32) + 0.5)),
// i = 0 .. 256 (x from 0 to 8 in steps of 1/32). Literals generated once by
// firmware/tools/gen_activation_table.py, which also checks that no entry is
// within 1e-6 LSB of a rounding tie; activation_test.cc re-derives the table
// with std::tanh. Non-decreasing, which makes the interpolation monotone.
const std::int16_t kTanhQ15Table[kTanhTableEntries] = {
    0, 1024, 2045, 3063, 4075, 5079, 6073, 7056,
    8025, 8980, 9919, 10840, 11743, 12625, 13486, 14326,
    15143, 15936, 16706, 17452, 18173, 18870, 19542, 20189,
    20813, 21411, 21986, 22538, 23066, 23571, 24054, 24516,
    24956, 25376, 25776, 26157, 26519, 26864, 27191, 27502,
    27797, 28076, 28341, 28592, 28830, 29055, 29268, 29470,
    29660, 29840, 30010, 30170, 30322, 30465, 30600, 30727,
    30847, 30960, 31067, 31167, 31262, 31351, 31435, 31515,
    31589, 31659, 31726, 31788, 31846, 31901, 31953, 32002,
    32048, 32091, 32132, 32170, 32206, 32240, 32271, 32301,
    32329, 32356, 32381, 32404, 32426, 32447, 32466, 32484,
    32501, 32517, 32532, 32547, 32560, 32573, 32584, 32596,
    32606, 32616, 32625, 32634, 32642, 32649, 32657, 32663,
    32670, 32676, 32681, 32686, 32691, 32696, 32700, 32704,
    32708, 32712, 32715, 32718, 32721, 32724, 32727, 32729,
    32732, 32734, 32736, 32738, 32740, 32741, 32743, 32745,
    32746, 32747, 32749, 32750, 32751, 32752, 32753, 32754,
    32755, 32755, 32756, 32757, 32758, 32758, 32759, 32759,
    32760, 32760, 32761, 32761, 32762, 32762, 32762, 32763,
    32763, 32763, 32764, 32764, 32764, 32764, 32765, 32765,
    32765, 32765, 32765, 32766, 32766, 32766, 32766, 32766,
    32766, 32766, 32766, 32767, 32767, 32767, 32767, 32767,
    32767, 32767, 32767, 32767, 32767, 32767, 32767, 32767,
    32767, 32767, 32767, 32767, 32767, 32767, 32767, 32767,
    32767, 32767, 32767, 32767, 32767, 32767, 32767, 32767,
    32767, 32767, 32767, 32767, 32767, 32767, 32767, 32767,
    32767, 32767, 32767, 32767, 32767, 32767, 32767, 32767,
    32767, 32767, 32767, 32767, 32767, 32767, 32767, 32767,
    32767, 32767, 32767, 32767, 32767, 32767, 32767, 32767,
    32767, 32767, 32767, 32767, 32767, 32767, 32767, 32767,
    32767, 32767, 32767, 32767, 32767, 32767, 32767, 32767,
    32767, 32767, 32767, 32767, 32767, 32767, 32767, 32767,
    32767,
};

}  // namespace detail

namespace {

// tanh(m / 2^(shift + 5)) in Q0.15 for a magnitude 0 <= m <= 32768, where
// the table step 1/32 spans 2^shift input units. shift = 7: m is |x| in
// Q3.12 (tanh). shift = 8: m is |x| in Q3.12 read as |x/2| in Q2.13
// (sigmoid). Result in [0, 32767].
std::int32_t tanh_magnitude(std::int32_t m, int shift) noexcept {
  const std::int32_t index = m >> shift;
  const std::int32_t frac = m & ((std::int32_t{1} << shift) - 1);
  const std::int32_t lo = detail::kTanhQ15Table[index];
  if (frac == 0) {
    return lo;  // also the only path for index 256 (m = 32768, shift 7)
  }
  // index + 1 <= 256 here: m < 32768 when frac != 0 (shift 7), index <= 128
  // (shift 8).
  const std::int32_t hi = detail::kTanhQ15Table[index + 1];
  // (hi - lo) in [0, 1024], frac < 256: the product fits easily in int32 and
  // is non-negative, so the shift rounds half up == half away from zero. The
  // result lies in [lo, hi] and is non-decreasing in m.
  return lo + (((hi - lo) * frac + (std::int32_t{1} << (shift - 1))) >> shift);
}

}  // namespace

std::int16_t tanh_q15(std::int16_t x) noexcept {
  const std::int32_t xi = x;
  const std::int32_t m = xi < 0 ? -xi : xi;  // [0, 32768], no overflow in int32
  const std::int32_t y = tanh_magnitude(m, 7);
  return static_cast<std::int16_t>(xi < 0 ? -y : y);  // y in [0, 32767]
}

std::int16_t sigmoid_q15(std::int16_t x) noexcept {
  const std::int32_t xi = x;
  const std::int32_t m = xi < 0 ? -xi : xi;
  const std::int32_t t_mag = tanh_magnitude(m, 8);  // tanh(|x|/2), [0, 32767]
  const std::int32_t t = xi < 0 ? -t_mag : t_mag;
  // (1 + t) / 2 in Q0.15: (32768 + t) / 2, rounded half up. |t| <= 32746
  // (tanh(4) rounded) gives [11, 32757]; the clamp only guards the
  // representable +1.0 (32768) in case the table ever changes.
  const std::int32_t y = (std::int32_t{32768} + t + 1) >> 1;
  return static_cast<std::int16_t>(y > 32767 ? 32767 : y);  // saturate +1.0
}

}  // namespace hadynet::fixed
