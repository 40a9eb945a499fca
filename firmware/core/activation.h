// Fixed-point activations for the LSTM (docs/architecture.md §6): tanh and sigmoid.
//
// Reference kernels (docs/architecture.md §6): integer-only at run time, no float, no
// heap, no exceptions, no target #ifdefs; bit-identical on host and MCU.
//
// Contract (both functions):
//  * Input  x: int16 in Q3.12 (FracBits 12): x_real = x / 4096,
//    range [-8, 8 - 2^-12], resolution 2^-12. Every int16 value is valid.
//  * Output y: int16 in Q0.15 (FracBits 15): y_real = y / 32768.
//      tanh_q15   : y in [-32767, 32767]  (tanh_q15(0) == 0)
//      sigmoid_q15: y in [11, 32757]      (sigmoid_q15(0) == 16384)
//    The extreme inputs give the rails: tanh_q15(32767) == 32767 (tanh(8)
//    rounds to +1.0 and saturates), tanh_q15(-32768) == -32767,
//    sigmoid_q15(32767) == 32757 and sigmoid_q15(-32768) == 11
//    (sigmoid(+-8) * 32768 = 32757.0 / 11.0). Nothing ever wraps. Inputs
//    outside [-8, 8) must be saturated into Q3.12 by the caller
//    (e.g. requantize_i16<From, 12>), which only moves the result towards the
//    rail: |tanh(8) - 1| < 2^-21, sigmoid(-8) ~= 3.35e-4 (raw 11).
//  * Accuracy, measured exhaustively over all 65536 inputs against double
//    std::tanh / 1/(1+exp(-x)) (test/firmware/activation_test.cc):
//      |tanh_q15(x)/32768    - tanh(x/4096)|         <= 2^-13 (4 LSB);
//                                                       measured 3.770 LSB
//      |sigmoid_q15(x)/32768 - 1/(1+exp(-x/4096))|   <= 5 * 2^-16 (2.5 LSB);
//                                                       measured 2.385 LSB
//    (1 LSB = 2^-15 of the output.)
//  * Both are monotone non-decreasing over all int16 inputs.
//  * tanh is exactly odd: tanh_q15(-x) == -tanh_q15(x) for every x in
//    [-32767, 32767]. x = -32768 (-8.0) has no int16 negation; its result is
//    -32767 == -tanh_q15(32767) (the output never reaches -32768, so the
//    negation of any result is representable).
//  * sigmoid is symmetric to 1 LSB: sigmoid_q15(x) + sigmoid_q15(-x) is 32768
//    or 32769 for x in [-32767, 32767].
//
// Method: one table of tanh on [0, 8] in Q0.15, 257 entries at steps of 1/32
// (514 bytes of const data, in flash), linear interpolation with rounding
// (round half up on non-negative values) between entries, odd symmetry for
// x < 0, and sigmoid(x) = (1 + tanh(x/2)) / 2 with the same table read at
// double resolution. The table is written as literals generated once by
// firmware/tools/gen_activation_table.py into activation_table.h (formula
// there).
#ifndef HADYNET_FIRMWARE_CORE_ACTIVATION_H_
#define HADYNET_FIRMWARE_CORE_ACTIVATION_H_

#include <cstdint>

#include "firmware/core/activation_table.h"  // detail::kTanhQ15Table

namespace hadynet::fixed {

// Fractional bits of the activation input (Q3.12) and output (Q0.15).
inline constexpr int kActivationInputFracBits = 12;
inline constexpr int kActivationOutputFracBits = 15;

// tanh(x / 4096) in Q0.15; see the contract above.
[[nodiscard]] std::int16_t tanh_q15(std::int16_t x) noexcept;

// 1 / (1 + exp(-x / 4096)) in Q0.15; see the contract above.
[[nodiscard]] std::int16_t sigmoid_q15(std::int16_t x) noexcept;

}  // namespace hadynet::fixed

#endif  // HADYNET_FIRMWARE_CORE_ACTIVATION_H_
