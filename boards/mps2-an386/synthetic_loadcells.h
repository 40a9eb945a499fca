// mps2-an386 has no ADC. So that the firmware's autonomous 5 Hz loop runs
// (and is tested in QEMU) with the same portable sources as on a board with
// loadcells, this board reports synthetic ones: deterministic voltages that
// go through the same kind of calibration data a real board has (volts to
// newtons with a zero offset), in the board's data, here.
//
//   scan n (the n-th call of board::read_loadcells since reset, from 0),
//   loadcell k:  millivolts = kZeroMillivolts + kStepMillivolts * ((7 n + 13 k) mod 41)
//                volts      = millivolts * 0.001f                   (one IEEE multiply)
//                newtons    = (volts - kLoadcellZeroVolts) * kLoadcellNewtonsPerVolt
//
// so each loadcell walks through 0 .. 4.8 N in 41 steps, every channel at its
// own phase. Every operation is one IEEE binary32 operation, written out
// (-ffp-contract=off), so a host test computes the same bits
// (test/boards/qemu_period_loop_test.cc). Pure constexpr data and code: no
// registers.
#ifndef HADYNET_BOARDS_MPS2_AN386_SYNTHETIC_LOADCELLS_H_
#define HADYNET_BOARDS_MPS2_AN386_SYNTHETIC_LOADCELLS_H_

#include <cstdint>

#include <cstddef>

namespace hadynet::board::mps2 {

inline constexpr std::int32_t kZeroMillivolts = 1650;  // no load
inline constexpr std::int32_t kStepMillivolts = 12;

// Calibration of the (synthetic) amplifiers, the same for every loadcell:
// zero-load voltage and gain.
inline constexpr float kLoadcellZeroVolts = 1.65f;
inline constexpr float kLoadcellNewtonsPerVolt = 10.0f;

// The voltage of loadcell k in scan n.
constexpr float synthetic_loadcell_volts(std::uint32_t scan, int k) noexcept {
  const std::uint32_t phase = (7u * (scan % 41u) + 13u * static_cast<std::uint32_t>(k)) % 41u;
  const std::int32_t millivolts = kZeroMillivolts + kStepMillivolts * static_cast<std::int32_t>(phase);
  return static_cast<float>(millivolts) * 0.001f;
}

// Scan n of N loadcells in newtons, as board::read_loadcells reports it
// (the board scans board_config.h's kLoadcells).
template <std::size_t N>
constexpr void synthetic_loadcells(std::uint32_t scan, float (&newtons)[N]) noexcept {
  for (std::size_t k = 0; k < N; ++k) {
    const float volts = synthetic_loadcell_volts(scan, static_cast<int>(k));
    newtons[k] = (volts - kLoadcellZeroVolts) * kLoadcellNewtonsPerVolt;
  }
}

}  // namespace hadynet::board::mps2

#endif  // HADYNET_BOARDS_MPS2_AN386_SYNTHETIC_LOADCELLS_H_
