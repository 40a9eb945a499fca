// Host side of the HID telemetry (telemetry_report.h): 64-byte reports in,
// whole app::PeriodRecords out (decoded by link::decode_period_result, as a
// 0x88 reply is), drops counted from the sequence numbers. Pure code (no
// I/O, no heap) for `hadynet monitor` and the tests.
//
// Counting: a record is delivered when all parts of its set arrived in order
// and its payload decodes (right mode and flag bits, the payload's sequence
// equal to the header's; otherwise the set counts in `bad_payloads` and is
// not delivered). `dropped` adds, for each delivered record, the sequence
// numbers skipped since the previous delivered one (sets lost whole or in
// part, or not decodable). A sequence number lower than the previous one is
// a device restart (counted in `restarts`, no drops); an equal one a
// duplicate (ignored).
#ifndef HADYNET_FIRMWARE_USB_TELEMETRY_DECODER_H_
#define HADYNET_FIRMWARE_USB_TELEMETRY_DECODER_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/app/period_record.h"
#include "firmware/link/messages.h"
#include "firmware/usb/telemetry_report.h"

namespace hadynet::usb {

struct TelemetryStats {
  std::uint64_t records = 0;          // delivered records
  std::uint64_t dropped = 0;          // sequence numbers never delivered between delivered records
  std::uint64_t bad_reports = 0;      // wrong size, version, part count or part length
  std::uint64_t bad_payloads = 0;     // whole sets whose payload did not decode (not delivered)
  std::uint64_t incomplete_sets = 0;  // sets abandoned because a part was missing
  std::uint64_t duplicates = 0;
  std::uint64_t restarts = 0;
};

template <firmware::GeneratedModel M>
class TelemetryDecoder {
 public:
  using Layout = TelemetryLayout<M>;
  // kBadReport: this report was malformed, or it completed a set whose
  // payload did not decode.
  enum class Event : std::uint8_t { kNone, kRecord, kBadReport };

  // One input report as read from the device (hidraw: 64 bytes).
  Event push(std::span<const std::uint8_t> report) noexcept {
    if (report.size() != kTelemetryReportSize || report[0] != kTelemetryFormatVersion || report[2] != Layout::kParts ||
        report[1] >= Layout::kParts || report[3] != Layout::part_length(report[1])) {
      ++stats_.bad_reports;
      return Event::kBadReport;
    }
    const std::size_t part = report[1];
    const std::uint32_t sequence = get_le32(report.data() + 4);
    if (part == 0) {
      if (in_set_) ++stats_.incomplete_sets;
      in_set_ = true;
      set_sequence_ = sequence;
      next_part_ = 0;
    } else if (!in_set_ || sequence != set_sequence_ || part != next_part_) {
      if (in_set_) ++stats_.incomplete_sets;
      in_set_ = false;
      return Event::kNone;
    }
    for (std::size_t i = 0; i < report[3]; ++i) {
      payload_[part * kTelemetryPartPayload + i] = report[kTelemetryHeaderSize + i];
    }
    next_part_ = part + 1;
    if (next_part_ < Layout::kParts) return Event::kNone;
    in_set_ = false;
    return deliver(sequence);
  }

  // The newest delivered record (all zero before the first).
  const app::PeriodRecord<M>& record() const noexcept { return record_; }
  const TelemetryStats& stats() const noexcept { return stats_; }

 private:
  Event deliver(std::uint32_t sequence) noexcept {
    if (!link::decode_period_result<M>(std::span<const std::uint8_t>(payload_, Layout::kPayloadSize), candidate_) ||
        candidate_.sequence != sequence) {
      ++stats_.bad_payloads;
      return Event::kBadReport;
    }
    if (have_last_) {
      const auto diff = static_cast<std::int32_t>(sequence - last_sequence_);
      if (diff == 0) {
        ++stats_.duplicates;
        return Event::kNone;
      }
      if (diff < 0) {
        ++stats_.restarts;
      } else {
        stats_.dropped += static_cast<std::uint64_t>(diff - 1);
      }
    }
    have_last_ = true;
    last_sequence_ = sequence;
    record_ = candidate_;
    ++stats_.records;
    return Event::kRecord;
  }

  std::uint8_t payload_[Layout::kParts * kTelemetryPartPayload] = {};
  bool in_set_ = false;
  std::uint32_t set_sequence_ = 0;
  std::size_t next_part_ = 0;
  bool have_last_ = false;
  std::uint32_t last_sequence_ = 0;
  app::PeriodRecord<M> candidate_{};  // the set being decoded
  app::PeriodRecord<M> record_{};
  TelemetryStats stats_{};
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_TELEMETRY_DECODER_H_
