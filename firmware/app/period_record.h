// The result of one period of the firmware's own 5 Hz loop (period_loop.h):
// a plain struct, sized from the generated model, that the link sends on
// request (docs/protocol.md, 0x88) and the USB HID telemetry class encodes
// into its reports. Nothing in it points anywhere; copy it freely.
//
// Contract:
//   * One record per period the loop ran (board::period_elapsed() true),
//     whether or not the runtime stepped. `sequence` is 1 for the first, +1
//     for each next one; 0 means "no period has run yet" (all else zero).
//   * `period` is the board's period index: sequence + missed_periods (a
//     boundary the main loop was too busy to see still counts).
//   * The runtime stepped (kRecordStepped) only with a muscle state received
//     over the link AND a loadcell reading. Without a muscle state since the
//     last reset / sensor frame: kRecordNoMuscleState, no step. Without a
//     reading (a board with no loadcells or no scan yet): kRecordNoLoadcells,
//     no step.
//   * A muscle state is fresh if it arrived during the period that this
//     record closes (after the previous record). An older one is still used,
//     never silently: kRecordStaleMuscleState and muscle_state_age >= 1
//     (records since it arrived).
//   * prediction, d, contact and command are the runtime's StepResult of that
//     step, bit for bit (the same as a host-driven sensor frame 0x02 with the
//     same data); fields whose valid flag is clear are 0. So are the
//     adaptation's count and recognition (StepResult::adapt_updates,
//     recognition): pushed with every record, where the link's adapt status
//     (0x89) has them only on request.
//   * kRecordOverrun: this period's work (from the period boundary to the end
//     of the step) took longer than one period (0.2 s); `overruns` counts such
//     periods since start. `missed_periods` is board::overrun_periods(): the
//     period boundaries the main loop never saw.
// The overrun flag and count are final after PeriodLoop::end_period(); take
// the record (latest()) after that.
#ifndef HADYNET_FIRMWARE_APP_PERIOD_RECORD_H_
#define HADYNET_FIRMWARE_APP_PERIOD_RECORD_H_

#include <cstdint>

#include "firmware/app/channel_layout.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_contract.h"

namespace hadynet::app {

// PeriodRecord::flags (the wire's bit numbers, docs/protocol.md 0x88).
inline constexpr std::uint16_t kRecordPredictionValid = 1u << 0;  // prediction holds y_est_t
inline constexpr std::uint16_t kRecordDistanceValid = 1u << 1;    // d holds the contact distance
inline constexpr std::uint16_t kRecordContact = 1u << 2;          // d > C_detect
inline constexpr std::uint16_t kRecordCommandValid = 1u << 3;     // command holds the stabiliser's u_t
inline constexpr std::uint16_t kRecordStepped = 1u << 4;          // the runtime ran this period
inline constexpr std::uint16_t kRecordStaleMuscleState = 1u << 5;  // stepped with a muscle state older than one period
inline constexpr std::uint16_t kRecordNoMuscleState = 1u << 6;     // none received: not stepped
inline constexpr std::uint16_t kRecordNoLoadcells = 1u << 7;       // no loadcell reading: not stepped
inline constexpr std::uint16_t kRecordOverrun = 1u << 8;           // this period's work exceeded 0.2 s
inline constexpr std::uint16_t kRecordRecognition = 1u << 9;       // the adapted PB named a trained state
inline constexpr std::uint16_t kRecordKnownFlags = (1u << 10) - 1;

// PeriodRecord::other_object_state when every PB-table row names one object.
inline constexpr std::uint16_t kRecordNoOtherObject = 0xFFFF;

template <firmware::GeneratedModel M>
struct PeriodRecord {
  static constexpr int kLoadcells = ChannelLayout<M>::kLoadcells;
  static constexpr int kLoadcellSlots = ChannelLayout<M>::kLoadcellSlots;

  std::uint32_t sequence = 0;          // 1, 2, ... per period the loop ran; 0: none yet
  std::uint32_t period = 0;            // board period index: sequence + missed_periods
  firmware::Mode mode = firmware::Mode::kObserve;  // the runtime's mode in this period
  std::uint16_t flags = 0;             // kRecord*
  std::uint32_t muscle_state_age = 0;  // records since the muscle state used arrived (0: fresh)
  std::uint32_t overruns = 0;          // periods since start whose work exceeded one period
  std::uint32_t missed_periods = 0;    // board::overrun_periods() at this period
  float loadcells_N[kLoadcellSlots] = {};  // [0, kLoadcells): as stepped, board reading minus tare offset, N ("fc<k>")
  float d = 0.0f;                      // Mahalanobis distance, standardised units
  float prediction[M::kY] = {};        // y_est_t, physical (log units)
  float command[M::kU] = {};           // u_t, physical
  // On-device PB adaptation (docs/firmware.md), from the same step. With
  // kRecordRecognition: the adapted PB's nearest PB-table row and the
  // nearest row naming another object (kRecordNoOtherObject: none), with
  // their distances (standardised PB units); without it these four are 0.
  std::uint32_t adapt_updates = 0;         // PB updates since adaptation began (0: off or none yet)
  std::uint16_t recognized_state = 0;      // row of the model's PB table (its state name)
  float recognized_distance = 0.0f;
  std::uint16_t other_object_state = 0;
  float other_object_distance = 0.0f;

  constexpr bool has(std::uint16_t flag) const noexcept { return (flags & flag) != 0; }
};

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_PERIOD_RECORD_H_
