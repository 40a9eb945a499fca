// The HID telemetry wire format: one TelemetryRecord becomes a *report set*
// of 64-byte input reports (no report ID), each
//
//   offset 0  u8   format version (kTelemetryFormatVersion)
//   offset 1  u8   part index, 0 .. part count - 1
//   offset 2  u8   part count of the set
//   offset 3  u8   payload bytes in this part (1 .. 56)
//   offset 4  u32  sequence number of the record (the same in every part)
//   offset 8  56 bytes of the record payload, the rest of the last part 0
//
// and the record payload (little-endian, floats IEEE 754 binary32):
//
//   0  u32 period   4  u8 mode   5  u8 reserved (0)   6  u16 flags   8  f32 d
//   12 f32 prediction[kY]   12 + 4 kY  f32 command[kU]     (12 + 4 (kY + kU) bytes)
//
// Sizes come from the model's compile-time shapes (the hand: kY 27, kU 8:
// 152 payload bytes, 3 reports per set). Pure code, shared by the firmware
// (encoder) and host tools (telemetry_decoder.h).
#ifndef HADYNET_FIRMWARE_USB_TELEMETRY_REPORT_H_
#define HADYNET_FIRMWARE_USB_TELEMETRY_REPORT_H_

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/usb/telemetry_record.h"
#include "firmware/usb/usb_spec.h"

namespace hadynet::usb {

inline constexpr std::uint8_t kTelemetryFormatVersion = 1;
inline constexpr std::size_t kTelemetryReportSize = 64;
inline constexpr std::size_t kTelemetryHeaderSize = 8;
inline constexpr std::size_t kTelemetryPartPayload = kTelemetryReportSize - kTelemetryHeaderSize;  // 56

template <firmware::GeneratedModel M>
struct TelemetryLayout {
  static constexpr std::size_t kPeriod = 0;
  static constexpr std::size_t kMode = 4;
  static constexpr std::size_t kReserved = 5;
  static constexpr std::size_t kFlags = 6;
  static constexpr std::size_t kD = 8;
  static constexpr std::size_t kPrediction = 12;
  static constexpr std::size_t kCommand = kPrediction + 4 * static_cast<std::size_t>(M::kY);
  static constexpr std::size_t kPayloadSize = kCommand + 4 * static_cast<std::size_t>(M::kU);
  static constexpr std::size_t kParts = (kPayloadSize + kTelemetryPartPayload - 1) / kTelemetryPartPayload;
  static_assert(kParts <= 255, "the part count is one byte");
};

// The record's payload bytes (layout above) into `out` (kPayloadSize bytes).
template <firmware::GeneratedModel M>
constexpr void encode_telemetry_payload(const TelemetryRecord<M>& r, std::span<std::uint8_t> out) noexcept {
  using L = TelemetryLayout<M>;
  std::uint8_t* p = out.data();
  put_u32(p + L::kPeriod, r.period);
  p[L::kMode] = r.mode;
  p[L::kReserved] = 0;
  put_u16(p + L::kFlags, r.flags);
  put_u32(p + L::kD, std::bit_cast<std::uint32_t>(r.d));
  for (int i = 0; i < M::kY; ++i) put_u32(p + L::kPrediction + 4 * i, std::bit_cast<std::uint32_t>(r.prediction[i]));
  for (int i = 0; i < M::kU; ++i) put_u32(p + L::kCommand + 4 * i, std::bit_cast<std::uint32_t>(r.command[i]));
}

// The record's report set: L::kParts reports of 64 bytes into `reports`.
template <firmware::GeneratedModel M>
constexpr void encode_telemetry_reports(const TelemetryRecord<M>& r,
                                        std::span<std::uint8_t, TelemetryLayout<M>::kParts * kTelemetryReportSize>
                                            reports) noexcept {
  using L = TelemetryLayout<M>;
  std::uint8_t payload[L::kPayloadSize] = {};
  encode_telemetry_payload<M>(r, payload);
  for (std::size_t part = 0; part < L::kParts; ++part) {
    std::uint8_t* rep = reports.data() + part * kTelemetryReportSize;
    const std::size_t begin = part * kTelemetryPartPayload;
    const std::size_t n = L::kPayloadSize - begin < kTelemetryPartPayload ? L::kPayloadSize - begin
                                                                          : kTelemetryPartPayload;
    rep[0] = kTelemetryFormatVersion;
    rep[1] = static_cast<std::uint8_t>(part);
    rep[2] = static_cast<std::uint8_t>(L::kParts);
    rep[3] = static_cast<std::uint8_t>(n);
    put_u32(rep + 4, r.sequence);
    for (std::size_t i = 0; i < kTelemetryPartPayload; ++i) {
      rep[kTelemetryHeaderSize + i] = i < n ? payload[begin + i] : 0;
    }
  }
}

// The record from its payload bytes (the inverse of encode_telemetry_payload).
template <firmware::GeneratedModel M>
constexpr void decode_telemetry_payload(std::span<const std::uint8_t> in, std::uint32_t sequence,
                                        TelemetryRecord<M>& r) noexcept {
  using L = TelemetryLayout<M>;
  const std::uint8_t* p = in.data();
  r.sequence = sequence;
  r.period = get_u32(p + L::kPeriod);
  r.mode = p[L::kMode];
  r.flags = get_u16(p + L::kFlags);
  r.d = std::bit_cast<float>(get_u32(p + L::kD));
  for (int i = 0; i < M::kY; ++i) r.prediction[i] = std::bit_cast<float>(get_u32(p + L::kPrediction + 4 * i));
  for (int i = 0; i < M::kU; ++i) r.command[i] = std::bit_cast<float>(get_u32(p + L::kCommand + 4 * i));
}

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_TELEMETRY_REPORT_H_
