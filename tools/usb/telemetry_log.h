// The telemetry stream (app::PeriodRecord per control period, as HID reports
// or the link's 0x88 reply carry it) as HADYNET logs (docs/log-format.md), so
// every tool reads what `hadynet monitor` recorded.
//
// Columns, named from the generated model (M::kYNames, M::kUNames):
//   t                      period index x the control period (0.2 s), s
//   <loadcell names>       the measured loadcells as stepped (e.g. fc0..fc8),
//                          the observed group(s) of the log
//   aux_d                  contact distance d (standardised units)
//   aux_contact            1 if d > C_detect
//   aux_mode               0 observe, 1 detect, 2 control
//   aux_flags              the record's flag bits (firmware/app/period_record.h)
//   aux_pred_<y name>      the model's prediction y_est_t, log units
//   aux_cmd_<u name>       the stabiliser's command u_t, log units
//   aux_adapt_updates      PB updates of the on-device adaptation (0: off)
//   aux_recognized_state   the adapted PB's nearest PB-table row (the model's
//                          state names index it), with the flag kRecordRecognition
//   aux_recognized_distance  its distance, standardised PB units
//   aux_other_object_state   the nearest row naming another object (-1: none)
//   aux_other_object_distance  its distance
// Fields a record does not hold (no prediction, no command) are written as 0
// with the flag bit saying so, never invented otherwise.
//
// A log must have a regular time axis, so the stream is cut into SEGMENTS at
// every gap in the period index (reports dropped by a slow host, periods
// the board missed) and at any non-finite value (that record is left out
// and counted); each segment is one log.
#ifndef HADYNET_TOOLS_USB_TELEMETRY_LOG_H_
#define HADYNET_TOOLS_USB_TELEMETRY_LOG_H_

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "boards/board.h"
#include "datalog/log_table.h"
#include "firmware/app/channel_layout.h"
#include "firmware/app/period_record.h"

namespace hadynet::tools::usb {

inline constexpr double kControlPeriodS = 1.0 / board::kPeriodHz;

template <firmware::GeneratedModel M>
class TelemetryLog {
 public:
  using Record = app::PeriodRecord<M>;
  using Layout = app::ChannelLayout<M>;

  // `source`: the `source` metadata value (e.g. "hadynet monitor, serial X").
  explicit TelemetryLog(std::string source) : source_(std::move(source)) {}

  // Appends a record; starts a new segment on a gap in `period` or after a
  // skipped record. Returns false if the record was skipped (non-finite).
  bool add(const Record& r) {
    std::vector<double> row;
    row.reserve(columns().size());
    row.push_back(static_cast<double>(r.period) * kControlPeriodS);
    for (int k = 0; k < Layout::kLoadcells; ++k) row.push_back(r.loadcells_N[k]);
    row.push_back(r.d);
    row.push_back(r.has(app::kRecordContact) ? 1.0 : 0.0);
    row.push_back(static_cast<double>(static_cast<std::uint8_t>(r.mode)));
    row.push_back(static_cast<double>(r.flags));
    for (int i = 0; i < M::kY; ++i) row.push_back(r.prediction[i]);
    for (int i = 0; i < M::kU; ++i) row.push_back(r.command[i]);
    row.push_back(static_cast<double>(r.adapt_updates));
    row.push_back(static_cast<double>(r.recognized_state));
    row.push_back(r.recognized_distance);
    row.push_back(r.other_object_state == app::kRecordNoOtherObject ? -1.0 : static_cast<double>(r.other_object_state));
    row.push_back(r.other_object_distance);
    for (const double v : row) {
      if (!std::isfinite(v)) {
        ++skipped_;
        break_segment_ = true;
        return false;
      }
    }
    if (segments_.empty() || break_segment_ || r.period != last_period_ + 1) new_segment();
    break_segment_ = false;
    last_period_ = r.period;
    segments_.back().append_row(row);
    return true;
  }

  const std::vector<datalog::LogTable>& segments() const { return segments_; }
  std::uint64_t skipped_records() const { return skipped_; }

  // The header (same for every segment).
  static const std::vector<std::string>& columns() {
    static const std::vector<std::string> names = [] {
      std::vector<std::string> c{"t"};
      for (int k = 0; k < Layout::kLoadcells; ++k) c.emplace_back(M::kYNames[Layout::kLoadcellY[k]]);
      c.insert(c.end(), {"aux_d", "aux_contact", "aux_mode", "aux_flags"});
      for (int i = 0; i < M::kY; ++i) c.push_back(std::string("aux_pred_") + M::kYNames[i]);
      for (int i = 0; i < M::kU; ++i) c.push_back(std::string("aux_cmd_") + M::kUNames[i]);
      c.insert(c.end(), {"aux_adapt_updates", "aux_recognized_state", "aux_recognized_distance",
                         "aux_other_object_state", "aux_other_object_distance"});
      return c;
    }();
    return names;
  }

 private:
  void new_segment() {
    datalog::LogTable table;
    table.metadata.set("format", "hadynet-log");
    table.metadata.set("format_version", "1");
    table.metadata.set("dt_s", "0.2");
    table.metadata.set("source", source_);
    table.metadata.set("segment", std::to_string(segments_.size() + 1));
    table.columns = columns();
    segments_.push_back(std::move(table));
  }

  static_assert(board::kPeriodHz == 5, "dt_s metadata text above says 0.2");

  std::string source_;
  std::vector<datalog::LogTable> segments_;
  std::uint32_t last_period_ = 0;
  bool break_segment_ = false;
  std::uint64_t skipped_ = 0;
};

}  // namespace hadynet::tools::usb

#endif  // HADYNET_TOOLS_USB_TELEMETRY_LOG_H_
