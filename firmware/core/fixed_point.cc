// Compiled instances of the fixed-point reference kernels.
//
// fixed_point.h is header-only; this file exists so that every build — host
// and Cortex-M4 alike, from the same source — really compiles the core with
// the firmware flags (-fno-exceptions -fno-rtti, warnings as errors) and so
// that the resulting library can be checked for heap/exception references
// (see firmware/cmake/check_no_alloc.cmake).
//
// Shapes follow docs/method.md, "Network" (x 37 + p 8 = 45 -> 128 encoder; LSTM input
// u 8 + p 8 = 16, 128 units, 4 gates; 128 -> 27 decoder). The Q formats are
// illustrative; codegen chooses the real ones from measured ranges.
#include "firmware/core/fixed_point.h"

#include <cstdint>

namespace hadynet::fixed {

namespace {
constexpr int kEncoderIn = 45;
constexpr int kHidden = 128;
constexpr int kGates = 4 * kHidden;
constexpr int kLstmIn = 16;
constexpr int kDecoderOut = 27;
}  // namespace

// Encoder and decoder: one matvec each, weights Q12, activations Q11, bias
// in accumulator format Q23.
template void matvec<12, 11, 11, kHidden, kEncoderIn>(const std::int16_t (&)[kHidden][kEncoderIn],
                                                      const std::int16_t (&)[kEncoderIn],
                                                      const std::int32_t (&)[kHidden],
                                                      std::int16_t (&)[kHidden]) noexcept;
template void matvec<12, 11, 11, kDecoderOut, kHidden>(const std::int16_t (&)[kDecoderOut][kHidden],
                                                       const std::int16_t (&)[kHidden],
                                                       const std::int32_t (&)[kDecoderOut],
                                                       std::int16_t (&)[kDecoderOut]) noexcept;

// LSTM gates: W_ih [u;p] + W_hh h summed exactly before one requantise.
template void matvec_accumulate<kGates, kLstmIn>(const std::int16_t (&)[kGates][kLstmIn],
                                                 const std::int16_t (&)[kLstmIn],
                                                 Accumulator (&)[kGates]) noexcept;
template void matvec_accumulate<kGates, kHidden>(const std::int16_t (&)[kGates][kHidden],
                                                 const std::int16_t (&)[kHidden],
                                                 Accumulator (&)[kGates]) noexcept;

// Element-wise LSTM products (gate Q15 x state Q11 -> Q11) and requantise.
template std::int16_t mul<15, 11, 11>(std::int16_t, std::int16_t) noexcept;
template std::int16_t requantize_i16<23, 11>(std::int64_t) noexcept;
template std::int32_t dot_q15<kHidden>(const std::int16_t (&)[kHidden], const std::int16_t (&)[kHidden]) noexcept;

}  // namespace hadynet::fixed
