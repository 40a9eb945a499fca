// The nine tendon loadcells on ADC1 inputs IN0..IN8 (PA0..PA7, PB0): ADC1
// scans them continuously (12 bits, 480-cycle samples at 21 MHz: about
// 4.7 k scans/s) and DMA2 stream 0 (channel 0) copies every conversion into
// a circular buffer of nine half-words; the 5 Hz loop reads the buffer.
// A read may mix two consecutive scans (each channel's value is one
// conversion, copied atomically); at 5 Hz against 4.7 kHz that is harmless.
#ifndef HADYNET_BOARDS_STM32F405_LOADCELLS_H_
#define HADYNET_BOARDS_STM32F405_LOADCELLS_H_

#include <cstdint>

#include "board_config.h"

namespace hadynet::board::stm32 {

using config::kLoadcells;

// ADC1 input of loadcell i (the scan order).
inline constexpr std::uint8_t kLoadcellChannel[kLoadcells] = {0, 1, 2, 3, 4, 5, 6, 7, 8};

// Counts to newtons: loadcell_calibration.h.

// Configures the pins, ADC1 and DMA2 and starts the continuous scan
// (peripheral clocks must be running: configure_clocks() first).
void start_loadcell_scan() noexcept;

// The latest raw counts; false until every channel has been converted at
// least once (on QEMU 7.2, which models ADC1 but not DMA2: never).
bool loadcell_counts(std::uint16_t (&counts)[kLoadcells]) noexcept;

}  // namespace hadynet::board::stm32

#endif  // HADYNET_BOARDS_STM32F405_LOADCELLS_H_
