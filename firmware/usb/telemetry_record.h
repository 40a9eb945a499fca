// One control period's telemetry, as the HID interface reports it: sized from
// the generated model's compile-time shapes. Plain data; the application
// fills it from its period record (firmware/app/period_record.h) and hands
// it to HidTelemetry::publish().
#ifndef HADYNET_FIRMWARE_USB_TELEMETRY_RECORD_H_
#define HADYNET_FIRMWARE_USB_TELEMETRY_RECORD_H_

#include <cstddef>
#include <cstdint>

#include "firmware/core/model_contract.h"

namespace hadynet::usb {

// TelemetryRecord::flags (bit numbers are the wire's, docs/usb.md).
inline constexpr std::uint16_t kTelemetryPredictionValid = 1u << 0;  // prediction holds y_est_t
inline constexpr std::uint16_t kTelemetryDistanceValid = 1u << 1;    // d holds the contact distance
inline constexpr std::uint16_t kTelemetryCommandValid = 1u << 2;     // command holds u_t
inline constexpr std::uint16_t kTelemetryContact = 1u << 3;          // d > C_detect
inline constexpr std::uint16_t kTelemetryStaleInput = 1u << 4;       // stepped on a muscle state older than one period
inline constexpr std::uint16_t kTelemetryOverrun = 1u << 5;          // the period's work exceeded 0.2 s
inline constexpr std::uint16_t kTelemetryKnownFlags = (1u << 6) - 1;

template <firmware::GeneratedModel M>
struct TelemetryRecord {
  static constexpr int kY = M::kY;
  static constexpr int kU = M::kU;

  std::uint32_t sequence = 0;  // 1, 2, ... one per published record; the host counts gaps as drops
  std::uint32_t period = 0;    // the board's control-period index (0.2 s each)
  std::uint8_t mode = 0;       // firmware::Mode: 0 observe, 1 detect, 2 control
  std::uint16_t flags = 0;     // kTelemetry*
  float d = 0.0f;              // contact distance, standardised units
  float prediction[kY] = {};   // y_est_t, physical (log) units
  float command[kU] = {};      // u_t, physical units
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_TELEMETRY_RECORD_H_
