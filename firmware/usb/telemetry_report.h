// The HID telemetry wire format: one app::PeriodRecord (the record of one
// period of the firmware's 5 Hz loop, firmware/app/period_record.h) becomes
// a *report set* of 64-byte input reports (no report ID), each
//
//   offset 0  u8   format version (kTelemetryFormatVersion)
//   offset 1  u8   part index, 0 .. part count - 1
//   offset 2  u8   part count of the set
//   offset 3  u8   payload bytes in this part (1 .. 56)
//   offset 4  u32  sequence number of the record (the same in every part)
//   offset 8  56 bytes of the record payload, the rest of the last part 0
//
// The record payload is the link's period result (docs/protocol.md, 0x88),
// byte for byte: encoded and decoded by link::encode_period_result /
// link::decode_period_result (firmware/link/messages.h), the one layout of
// a PeriodRecord, flags with their kRecord* bit numbers. So a host decodes a
// record the same way from either transport. (firmware/usb already depends
// on firmware/link for CDC; the link's messages are pure header code.)
//
// Sizes come from the model's compile-time shapes (the hand: kLoadcells 9,
// kY 27, kU 8: 219 payload bytes, 4 reports per set). Pure code, shared by
// the firmware (encoder) and host tools (telemetry_decoder.h).
#ifndef HADYNET_FIRMWARE_USB_TELEMETRY_REPORT_H_
#define HADYNET_FIRMWARE_USB_TELEMETRY_REPORT_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/app/period_record.h"
#include "firmware/core/model_contract.h"
#include "firmware/link/messages.h"
#include "firmware/usb/usb_spec.h"

namespace hadynet::usb {

// 2: the payload became the 0x88 period result (1 was a shorter record with
// its own flag bits). 3: the period result gained the on-device adaptation's
// count and recognition (16 bytes).
inline constexpr std::uint8_t kTelemetryFormatVersion = 3;
inline constexpr std::size_t kTelemetryReportSize = 64;
inline constexpr std::size_t kTelemetryHeaderSize = 8;
inline constexpr std::size_t kTelemetryPartPayload = kTelemetryReportSize - kTelemetryHeaderSize;  // 56

template <firmware::GeneratedModel M>
struct TelemetryLayout {
  // The 0x88 payload of model M.
  static constexpr std::size_t kPayloadSize = link::PayloadSizes<M>::kPeriodResult;
  static constexpr std::size_t kParts = (kPayloadSize + kTelemetryPartPayload - 1) / kTelemetryPartPayload;
  static_assert(kParts <= 255, "the part count is one byte");

  // Payload bytes in part `part` (< kParts).
  static constexpr std::size_t part_length(std::size_t part) noexcept {
    const std::size_t begin = part * kTelemetryPartPayload;
    return kPayloadSize - begin < kTelemetryPartPayload ? kPayloadSize - begin : kTelemetryPartPayload;
  }
};

// The record's report set: L::kParts reports of 64 bytes into `reports`.
template <firmware::GeneratedModel M>
constexpr void encode_telemetry_reports(const app::PeriodRecord<M>& r,
                                        std::span<std::uint8_t, TelemetryLayout<M>::kParts * kTelemetryReportSize>
                                            reports) noexcept {
  using L = TelemetryLayout<M>;
  std::uint8_t payload[L::kPayloadSize] = {};
  // Always L::kPayloadSize (the buffer is exactly that size).
  (void)link::encode_period_result<M>(r, payload);
  for (std::size_t part = 0; part < L::kParts; ++part) {
    std::uint8_t* rep = reports.data() + part * kTelemetryReportSize;
    const std::size_t begin = part * kTelemetryPartPayload;
    const std::size_t n = L::part_length(part);
    rep[0] = kTelemetryFormatVersion;
    rep[1] = static_cast<std::uint8_t>(part);
    rep[2] = static_cast<std::uint8_t>(L::kParts);
    rep[3] = static_cast<std::uint8_t>(n);
    put_le32(rep + 4, r.sequence);
    for (std::size_t i = 0; i < kTelemetryPartPayload; ++i) {
      rep[kTelemetryHeaderSize + i] = i < n ? payload[begin + i] : 0;
    }
  }
}

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_TELEMETRY_REPORT_H_
