// The nine loadcells' calibration: THE place for this board's scaling of
// ADC counts to newtons (board::read_loadcells):
//
//   volts   = counts * kAdcVoltsPerCount                   (12-bit ADC, 3.3 V reference)
//   newtons = (volts - kLoadcellZeroVolts[k]) * kLoadcellNewtonsPerVolt[k]
//
// PLACEHOLDERS until the hand's loadcell amplifier is specified: zero load
// at mid-scale (1.65 V), +-50 N over the 0..3.3 V range. Offsets that drift
// in use are not corrected here: the link's tare (docs/protocol.md, 0x07)
// subtracts the reading at tare time in the portable loop.
#ifndef HADYNET_BOARDS_STM32F405_LOADCELL_CALIBRATION_H_
#define HADYNET_BOARDS_STM32F405_LOADCELL_CALIBRATION_H_

#include "board_config.h"

namespace hadynet::board::stm32 {

using config::kLoadcells;

inline constexpr float kAdcVoltsPerCount = 3.3f / 4096.0f;

inline constexpr float kLoadcellZeroVolts[kLoadcells] = {1.65f, 1.65f, 1.65f, 1.65f, 1.65f,
                                                          1.65f, 1.65f, 1.65f, 1.65f};
inline constexpr float kLoadcellNewtonsPerVolt[kLoadcells] = {
    100.0f / 3.3f, 100.0f / 3.3f, 100.0f / 3.3f, 100.0f / 3.3f, 100.0f / 3.3f,
    100.0f / 3.3f, 100.0f / 3.3f, 100.0f / 3.3f, 100.0f / 3.3f};

}  // namespace hadynet::board::stm32

#endif  // HADYNET_BOARDS_STM32F405_LOADCELL_CALIBRATION_H_
