// HID telemetry (HID 1.11): a vendor-defined interface with one interrupt IN
// endpoint that sends one report set (telemetry_report.h) per published
// record: the app::PeriodRecord of each period of the firmware's 5 Hz loop
// (PeriodLoop::latest() after end_period()).
//
// publish() while a set is still being sent keeps the newest record as
// pending and sends it next; a pending record replaced by a newer one is
// lost (counted in overwritten(); the host sees the gap in the sequence
// numbers). Class requests: GET_REPORT (input, no report ID: part 0 of the
// newest record's set), SET_IDLE / GET_IDLE (the rate is kept and returned;
// reports go out when there is a new record, whatever the rate), and the
// standard GET_DESCRIPTOR for the HID and report descriptors. No boot
// protocol, no output or feature reports: their requests STALL.
#ifndef HADYNET_FIRMWARE_USB_HID_TELEMETRY_H_
#define HADYNET_FIRMWARE_USB_HID_TELEMETRY_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/app/period_record.h"
#include "firmware/usb/device_controller.h"
#include "firmware/usb/telemetry_report.h"
#include "firmware/usb/usb_function.h"
#include "firmware/usb/usb_spec.h"

namespace hadynet::usb {

namespace hid {
inline constexpr std::uint8_t kClassHid = 0x03;
inline constexpr std::uint8_t kGetReport = 0x01;
inline constexpr std::uint8_t kGetIdle = 0x02;
inline constexpr std::uint8_t kGetProtocol = 0x03;
inline constexpr std::uint8_t kSetReport = 0x09;
inline constexpr std::uint8_t kSetIdle = 0x0A;
inline constexpr std::uint8_t kSetProtocol = 0x0B;
inline constexpr std::uint8_t kReportTypeInput = 1;
inline constexpr std::uint8_t kPollIntervalMs = 10;  // bInterval of the IN endpoint

// Vendor-defined (usage page 0xFF00): one input report of 64 bytes, no ID.
inline constexpr std::array<std::uint8_t, 21> kReportDescriptor = {
    0x06, 0x00, 0xFF,  // Usage Page (Vendor Defined 0xFF00)
    0x09, 0x01,        // Usage (0x01: HADYNET telemetry)
    0xA1, 0x01,        // Collection (Application)
    0x09, 0x02,        //   Usage (0x02: report set part)
    0x15, 0x00,        //   Logical Minimum (0)
    0x26, 0xFF, 0x00,  //   Logical Maximum (255)
    0x75, 0x08,        //   Report Size (8 bits)
    0x95, 0x40,        //   Report Count (64)
    0x81, 0x02,        //   Input (Data, Variable, Absolute)
    0xC0,              // End Collection
};
static_assert(kReportDescriptor[17] == kTelemetryReportSize, "Report Count = the report size");

// The HID class descriptor (HID 1.11 §6.2.1), inside the configuration.
inline constexpr std::array<std::uint8_t, 9> kHidDescriptor = {
    9, 0x21, 0x11, 0x01,  // bLength, HID, bcdHID 1.11
    0x00, 1,              // bCountryCode, bNumDescriptors
    0x22, static_cast<std::uint8_t>(kReportDescriptor.size()), 0x00,  // report descriptor, its length
};
}  // namespace hid

struct HidTelemetryLayout {
  std::uint8_t interface = 2;
  EndpointAddress report_in = 0x83;
};

template <firmware::GeneratedModel M>
class HidTelemetry final : public UsbFunction {
 public:
  using Layout = TelemetryLayout<M>;
  static constexpr std::size_t kSetBytes = Layout::kParts * kTelemetryReportSize;

  explicit HidTelemetry(const HidTelemetryLayout& layout) noexcept : layout_(layout) {}

  // The newest period's record; sent as soon as the endpoint is free.
  void publish(const app::PeriodRecord<M>& record) noexcept {
    latest_ = record;
    if (controller_ == nullptr) return;
    if (part_ < Layout::kParts) {  // a set is on its way
      if (has_pending_) ++overwritten_;
      has_pending_ = true;
      return;
    }
    start_set();
  }

  bool owns_interface(std::uint8_t interface) const noexcept override { return interface == layout_.interface; }
  bool owns_endpoint(EndpointAddress ep) const noexcept override { return ep == layout_.report_in; }

  ControlReply control_setup(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept override {
    if (s.recipient() != Recipient::kInterface || s.index != layout_.interface) return ControlReply::stall();
    if (s.kind() == RequestKind::kStandard) {
      if (s.request != request::kGetDescriptor || s.value_low() != 0) return ControlReply::stall();
      if (s.value_high() == descriptor::kHid) return copy(hid::kHidDescriptor, buffer);
      if (s.value_high() == descriptor::kHidReport) return copy(hid::kReportDescriptor, buffer);
      return ControlReply::stall();
    }
    switch (s.request) {
      case hid::kGetReport:
        if (!s.is_in() || s.value != (hid::kReportTypeInput << 8) || s.length == 0) break;
        {
          static_assert(kSetBytes <= kControlBufferSize, "a report set must fit the control buffer");
          // Before the first publish(): the empty record (sequence 0).
          encode_telemetry_reports<M>(latest_, buffer.template first<kSetBytes>());
          return ControlReply::data_in(kTelemetryReportSize);  // part 0
        }
      case hid::kSetIdle:
        if (s.is_in() || s.length != 0 || s.value_low() != 0) break;
        idle_4ms_ = s.value_high();
        return ControlReply::ack();
      case hid::kGetIdle:
        if (!s.is_in() || s.value != 0 || s.length != 1) break;
        buffer[0] = idle_4ms_;
        return ControlReply::data_in(1);
      default:  // GET/SET_PROTOCOL (not a boot device), SET_REPORT (no output reports)
        break;
    }
    return ControlReply::stall();
  }

  bool configure(DeviceController& controller) noexcept override {
    part_ = Layout::kParts;
    has_pending_ = false;
    halted_ = false;
    if (!controller.open_endpoint({layout_.report_in, EndpointType::kInterrupt,
                                   static_cast<std::uint16_t>(kTelemetryReportSize)})) {
      return false;
    }
    controller_ = &controller;
    return true;
  }

  void deconfigure() noexcept override {
    controller_ = nullptr;
    part_ = Layout::kParts;
    has_pending_ = false;
    halted_ = false;
  }

  void transfer_complete(EndpointAddress ep, std::size_t bytes) noexcept override {
    (void)bytes;
    if (ep != layout_.report_in || part_ >= Layout::kParts) return;
    ++part_;
    if (part_ < Layout::kParts) {
      send_part();
    } else {
      ++sets_sent_;
      if (has_pending_) start_set();
    }
  }

  void halt_changed(EndpointAddress ep, bool halted) noexcept override {
    if (ep != layout_.report_in) return;
    part_ = Layout::kParts;  // the set in flight is lost
    halted_ = halted;
    if (!halted && has_pending_) start_set();
  }

  std::uint8_t idle_rate_4ms() const noexcept { return idle_4ms_; }
  std::uint32_t sets_sent() const noexcept { return sets_sent_; }
  std::uint32_t overwritten() const noexcept { return overwritten_; }
  bool sending() const noexcept { return part_ < Layout::kParts; }

 private:
  template <std::size_t N>
  static ControlReply copy(const std::array<std::uint8_t, N>& bytes, std::span<std::uint8_t> buffer) noexcept {
    for (std::size_t i = 0; i < N; ++i) buffer[i] = bytes[i];
    return ControlReply::data_in(N);
  }

  void start_set() noexcept {
    has_pending_ = false;
    if (halted_ || controller_ == nullptr) {
      has_pending_ = true;
      return;
    }
    encode_telemetry_reports<M>(latest_, std::span<std::uint8_t, kSetBytes>(reports_));
    part_ = 0;
    send_part();
  }

  void send_part() noexcept {
    const std::span<std::uint8_t> report(reports_ + part_ * kTelemetryReportSize, kTelemetryReportSize);
    if (!controller_->start_transfer(layout_.report_in, report)) part_ = Layout::kParts;  // lost; next publish retries
  }

  HidTelemetryLayout layout_;
  DeviceController* controller_ = nullptr;  // set while configured
  app::PeriodRecord<M> latest_{};
  bool has_pending_ = false;
  bool halted_ = false;
  std::size_t part_ = Layout::kParts;  // the part on its way; kParts: idle
  std::uint8_t reports_[kSetBytes] = {};
  std::uint8_t idle_4ms_ = 0;
  std::uint32_t sets_sent_ = 0;
  std::uint32_t overwritten_ = 0;
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_HID_TELEMETRY_H_
