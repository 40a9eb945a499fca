// Reads the firmware's HID telemetry reports (docs/usb.md, "HID telemetry")
// through hidapi's libusb backend: finds the hand's telemetry interface
// (the project's VID:PID, interface composite::kHidInterface), opens it and
// hands out raw 64-byte input reports; decoding is TelemetryDecoder's job.
#ifndef HADYNET_TOOLS_USB_HID_TELEMETRY_READER_H_
#define HADYNET_TOOLS_USB_HID_TELEMETRY_READER_H_

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

struct hid_device_;

namespace hadynet::tools::usb {

class HidTelemetryReader {
 public:
  // Opens the telemetry interface of the hand whose serial number is
  // `serial`, or of the only hand attached when `serial` is empty. Throws
  // std::runtime_error in words: none attached, several without a serial,
  // no such serial, permission denied.
  explicit HidTelemetryReader(const std::string& serial);
  ~HidTelemetryReader();
  HidTelemetryReader(const HidTelemetryReader&) = delete;
  HidTelemetryReader& operator=(const HidTelemetryReader&) = delete;

  // One input report into `report` within `timeout_ms`: its size, or 0 on
  // timeout. Throws std::runtime_error if the device is gone or fails.
  std::size_t read(std::span<std::uint8_t> report, int timeout_ms);

  const std::string& serial() const { return serial_; }

 private:
  hid_device_* device_ = nullptr;
  std::string serial_;
};

}  // namespace hadynet::tools::usb

#endif  // HADYNET_TOOLS_USB_HID_TELEMETRY_READER_H_
