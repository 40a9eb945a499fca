// The firmware's own 5 Hz loop as pure code (no board, no I/O): every period
// it assembles one sensor frame from the board's loadcells and the newest
// muscle state received over the link (channel_layout.h), steps the runtime
// and keeps the result as a PeriodRecord (period_record.h, the contract of
// flags, staleness and overruns).
//
//   link (dispatcher.h):  receive_muscle_state(), forget_muscle_state(),
//                         tare(), clear_tare(), latest()
//   main loop, when board::period_elapsed():
//       run_period(board reading, board::overrun_periods());
//       ... end_period(ticks the period's work took, ticks per period);
//
// The host-driven sensor frame (0x02) steps the same runtime; the dispatcher
// calls forget_muscle_state() for it (and for reset), so the loop never steps
// a runtime that a host is driving frame by frame.
//
// Tare: loadcell k enters the frame as reading_k - offset_k (newtons). The
// offsets start at 0 (the board's calibration alone, boards/<board>/); tare()
// sets them to the latest reading, so that reading becomes zero; clear_tare()
// sets them back to 0.
#ifndef HADYNET_FIRMWARE_APP_PERIOD_LOOP_H_
#define HADYNET_FIRMWARE_APP_PERIOD_LOOP_H_

#include <cstdint>

#include "firmware/app/channel_layout.h"
#include "firmware/app/period_record.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_contract.h"

namespace hadynet::app {

template <firmware::GeneratedModel M>
class PeriodLoop {
 public:
  static constexpr int kLoadcells = ChannelLayout<M>::kLoadcells;
  static constexpr int kLoadcellSlots = ChannelLayout<M>::kLoadcellSlots;
  using Runtime = firmware::HadynetRuntime<M>;

  // One scan of the loadcells as the board reports it (board::read_loadcells):
  // newtons after the board's calibration (entries [0, kLoadcells)); valid
  // false if there was none.
  struct LoadcellReading {
    bool valid = false;
    float newtons[kLoadcellSlots] = {};
  };

  explicit PeriodLoop(Runtime& runtime) noexcept : runtime_(runtime) {}

  // The newest muscle state (replaces any older one). Returns the sequence
  // number of the record that will use it fresh (the next one).
  std::uint32_t receive_muscle_state(const MuscleState<M>& state) noexcept {
    muscle_ = state;
    has_muscle_ = true;
    muscle_stamp_ = record_.sequence;
    return record_.sequence + 1u;
  }
  // Until the next muscle state the loop does not step (kRecordNoMuscleState).
  void forget_muscle_state() noexcept { has_muscle_ = false; }
  bool has_muscle_state() const noexcept { return has_muscle_; }

  // Offsets := the latest reading. False (nothing changed) if no period has
  // had a reading yet.
  bool tare() noexcept {
    if (!last_reading_.valid) return false;
    for (int k = 0; k < kLoadcells; ++k) offsets_N_[k] = last_reading_.newtons[k];
    return true;
  }
  void clear_tare() noexcept {
    for (float& v : offsets_N_) v = 0.0f;
  }
  const float (&tare_offsets_N() const noexcept)[kLoadcellSlots] { return offsets_N_; }

  // One period: `reading` from the board, `missed_periods` = the board's
  // count of period boundaries it never reported (cumulative).
  const PeriodRecord<M>& run_period(const LoadcellReading& reading, std::uint32_t missed_periods) noexcept {
    PeriodRecord<M> r;
    r.sequence = record_.sequence + 1u;
    r.missed_periods = missed_periods;
    r.period = r.sequence + missed_periods;
    r.overruns = overruns_;
    r.mode = runtime_.mode();
    if (reading.valid) {
      last_reading_ = reading;
      for (int k = 0; k < kLoadcells; ++k) r.loadcells_N[k] = reading.newtons[k] - offsets_N_[k];
    } else {
      r.flags |= kRecordNoLoadcells;
    }
    if (!has_muscle_) r.flags |= kRecordNoMuscleState;

    if (reading.valid && has_muscle_) {
      r.muscle_state_age = record_.sequence - muscle_stamp_;
      if (r.muscle_state_age > 0) r.flags |= kRecordStaleMuscleState;
      firmware::SensorFrame<M> frame;
      assemble_frame<M>(muscle_, r.loadcells_N, frame);
      const firmware::StepResult<M> out = runtime_.step(frame);
      r.flags |= kRecordStepped;
      if (out.prediction_valid) r.flags |= kRecordPredictionValid;
      if (out.distance_valid) r.flags |= kRecordDistanceValid;
      if (out.contact) r.flags |= kRecordContact;
      if (out.command_valid) r.flags |= kRecordCommandValid;
      for (int i = 0; i < M::kY; ++i) r.prediction[i] = out.prediction[i];
      r.d = out.d;
      for (int i = 0; i < M::kU; ++i) r.command[i] = out.command[i];
      r.adapt_updates = out.adapt_updates;
      if (out.adapt_valid && out.recognition.valid) {
        r.flags |= kRecordRecognition;
        r.recognized_state = static_cast<std::uint16_t>(out.recognition.state);
        r.recognized_distance = out.recognition.distance;
        r.other_object_state = out.recognition.other_state < 0
                                   ? kRecordNoOtherObject
                                   : static_cast<std::uint16_t>(out.recognition.other_state);
        r.other_object_distance = out.recognition.other_distance;
      }
    }
    record_ = r;
    return record_;
  }

  // After run_period: the period's work took `work_ticks` of a clock with
  // `ticks_per_period` ticks per period; longer than one period is an
  // overrun (flagged in the latest record and counted).
  void end_period(std::uint32_t work_ticks, std::uint32_t ticks_per_period) noexcept {
    if (record_.sequence == 0 || work_ticks <= ticks_per_period) return;
    ++overruns_;
    record_.flags |= kRecordOverrun;
    record_.overruns = overruns_;
  }

  // The newest record (sequence 0 before the first period).
  const PeriodRecord<M>& latest() const noexcept { return record_; }

 private:
  Runtime& runtime_;
  MuscleState<M> muscle_{};
  bool has_muscle_ = false;
  std::uint32_t muscle_stamp_ = 0;  // record_.sequence when muscle_ arrived
  LoadcellReading last_reading_{};
  float offsets_N_[kLoadcellSlots] = {};
  std::uint32_t overruns_ = 0;
  PeriodRecord<M> record_{};
};

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_PERIOD_LOOP_H_
