// The USB device stack under arbitrary host behaviour: SETUP packets (raw and
// class requests aimed at the DFU and CDC interfaces), IN/OUT tokens with any
// data on any endpoint, bus resets, suspend/resume, service() calls,
// telemetry records, and flash faults (power cut, write error) of the
// simulated NOR flash. After every event the stack's invariants are checked;
// a violation aborts (libFuzzer reports it).
//
// Input: records, each an opcode byte and its arguments (usb_fuzz_input.h
// documents them via UsbFuzzOp); a truncated record ends the input.
#ifndef HADYNET_FUZZ_USB_FUZZ_HARNESS_H_
#define HADYNET_FUZZ_USB_FUZZ_HARNESS_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "firmware/app/period_record.h"
#include "firmware/flash/simulated_nor_flash.h"
#include "firmware/link/crc32.h"
#include "firmware/usb/dfu_image.h"
#include "firmware/usb/hadynet_usb_device.h"
#include "firmware/usb/host/fake_controller.h"
#include "firmware/usb/telemetry_decoder.h"
#include "hadynet_model_q15.h"

namespace hadynet::usb::fuzz {

using Q = model_q15::Model;

enum class UsbFuzzOp : std::uint8_t {
  kBusReset = 0,     // -
  kSetupRaw = 1,     // 8 bytes
  kInToken = 2,      // endpoint byte
  kOutToken = 3,     // endpoint byte, length byte (% 65), data
  kService = 4,      // -
  kPublish = 5,      // sequence u8 (an app::PeriodRecord: sequence, period, low flag bits)
  kSuspendResume = 6,  // flag byte
  kFlashFault = 7,   // kind byte (bit 0: power cut / write error), distance byte
  kPowerOn = 8,      // -
  kClassControl = 9,  // interface byte, request byte, value u16, length byte, data (OUT) — a whole transfer
  kEnumerate = 10,   // -
  kSpuriousCompletion = 11,  // endpoint byte, bytes u8: a completion outside the seam's contract
  kCount = 12,
};

// Echoes each received byte as 1..3 bytes (cheap stand-in for the link).
struct EchoEndpoint {
  static constexpr std::size_t kMaxReply = 3;
  std::span<const std::uint8_t> receive(std::uint8_t b) noexcept {
    reply[0] = b;
    reply[1] = static_cast<std::uint8_t>(~b);
    reply[2] = static_cast<std::uint8_t>(b ^ 0x55);
    return std::span<const std::uint8_t>(reply).first(1 + b % 3);
  }
  std::array<std::uint8_t, kMaxReply> reply{};
};

struct NullDetach final : DetachHook {
  void detach_to_bootloader(std::uint16_t) noexcept override { ++calls; }
  int calls = 0;
};

// A small flash: 1, 1, 2, 4 KiB sectors; DFU alt 0 writes sector 2, alt 1
// reads sector 3 (small, so the size limits are within the fuzzer's reach).
inline constexpr flash::FlashSector kFuzzSectors[] = {
    {0, 1024, 5}, {1024, 1024, 5}, {2048, 2048, 10}, {4096, 4096, 20}};
inline constexpr std::array<DfuTarget, 2> kFuzzTargets = {DfuTarget{{2048, 2048}, true, true},
                                                          DfuTarget{{4096, 4096}, false, true}};

[[noreturn]] inline void violated(const char* what) noexcept {
  (void)what;  // visible in the debugger / stack trace
  std::abort();
}

class UsbFuzzHarness {
 public:
  using Device = HadynetUsbDevice<Q, EchoEndpoint, EchoEndpoint::kMaxReply>;

  UsbFuzzHarness() noexcept
      : nor_(kFuzzSectors, cells_),
        device_(controller_, endpoint_, nor_, kFuzzTargets, detach_, kUid, "fuzz") {
    device_.start();
  }

  const Device& device() const noexcept { return device_; }
  const flash::SimulatedNorFlash& flash() const noexcept { return nor_; }

  void run(const std::uint8_t* data, std::size_t size) noexcept {
    std::span<const std::uint8_t> in(data, size);
    const auto take = [&in](std::size_t n, std::span<const std::uint8_t>& out) {
      if (in.size() < n) return false;
      out = in.first(n);
      in = in.subspan(n);
      return true;
    };
    std::span<const std::uint8_t> a;
    while (take(1, a)) {
      const auto op = static_cast<UsbFuzzOp>(a[0] % static_cast<std::uint8_t>(UsbFuzzOp::kCount));
      switch (op) {
        case UsbFuzzOp::kBusReset:
          controller_.bus_reset();
          break;
        case UsbFuzzOp::kSetupRaw:
          if (!take(8, a)) return;
          controller_.setup_raw(a.first<8>());
          break;
        case UsbFuzzOp::kInToken: {
          if (!take(1, a)) return;
          std::uint8_t packet[64];
          std::size_t n = 0;
          const EndpointAddress ep = static_cast<EndpointAddress>(a[0] & 0x8F);
          if (controller_.in_token(ep, packet, n) == host::Handshake::kAck && ep == composite::kHidReportIn) {
            telemetry_.push(std::span<const std::uint8_t>(packet, n));
          }
          if (n > 64) violated("IN packet larger than 64");
          break;
        }
        case UsbFuzzOp::kOutToken: {
          if (!take(2, a)) return;
          const EndpointAddress ep = static_cast<EndpointAddress>(a[0] & 0x0F);
          const std::size_t n = a[1] % 65;
          std::span<const std::uint8_t> d;
          if (!take(n, d)) return;
          controller_.out_token(ep, d);
          break;
        }
        case UsbFuzzOp::kService:
          device_.service();
          check_slots();
          break;
        case UsbFuzzOp::kPublish: {
          if (!take(1, a)) return;
          app::PeriodRecord<Q> r;
          r.sequence = a[0];
          r.period = a[0];
          r.flags = static_cast<std::uint16_t>(a[0] & app::kRecordKnownFlags);
          device_.publish(r);
          break;
        }
        case UsbFuzzOp::kSuspendResume:
          if (!take(1, a)) return;
          if (a[0] & 1) {
            controller_.suspend();
          } else {
            controller_.resume();
          }
          break;
        case UsbFuzzOp::kFlashFault:
          if (!take(2, a)) return;
          if (a[0] & 1) {
            nor_.cut_power_at(nor_.operation_count() + 1 + a[1] % 16);
          } else {
            nor_.fail_write_at(nor_.operation_count() + 1 + a[1] % 16);
          }
          break;
        case UsbFuzzOp::kPowerOn:
          nor_.power_on();
          break;
        case UsbFuzzOp::kClassControl: {
          if (!take(5, a)) return;
          const bool dir_in = (a[1] & 0x80) != 0;
          SetupPacket s{request_type(dir_in, RequestKind::kClass, Recipient::kInterface),
                        static_cast<std::uint8_t>(a[1] & 0x7F), static_cast<std::uint16_t>(a[2] | (a[3] << 8)),
                        static_cast<std::uint16_t>(a[0] % 6), static_cast<std::uint16_t>(a[4] * 2)};
          std::span<const std::uint8_t> d;
          if (!dir_in && !take(s.length < in.size() ? s.length : in.size(), d)) return;
          std::uint8_t reply[512];
          controller_.control(s, d, reply);
          break;
        }
        case UsbFuzzOp::kEnumerate:
          controller_.bus_reset();
          controller_.control({0x00, request::kSetAddress, 7, 0, 0}, {}, {});
          controller_.control({0x00, request::kSetConfiguration, 1, 0, 0}, {}, {});
          break;
        case UsbFuzzOp::kSpuriousCompletion:
          if (!take(2, a)) return;
          controller_.inject(ControllerEvent::transfer_complete(static_cast<EndpointAddress>(a[0] & 0x8F), a[1]));
          break;
        case UsbFuzzOp::kCount:
          break;
      }
      check_invariants();
    }
  }

 private:
  static constexpr std::array<std::uint8_t, kUniqueIdBytes> kUid = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};

  void check_invariants() const noexcept {
    const UsbDevice& d = device_.device();
    if (d.address() > 127) violated("address > 127");
    if (static_cast<int>(d.state()) > 2) violated("device state");
    if (static_cast<int>(d.control_stage()) > 5) violated("control stage");
    static constexpr EndpointAddress kEndpoints[] = {0x81, 0x02, 0x82, 0x83};
    if (d.state() == DeviceState::kConfigured) {
      for (const EndpointAddress ep : kEndpoints) {
        if (!controller_.endpoint_open(ep)) violated("configured with a closed endpoint");
      }
    } else {
      for (const EndpointAddress ep : kEndpoints) {
        if (controller_.transfer_active(ep)) violated("transfer on an endpoint of no configuration");
      }
    }
    const DfuMode& dfu = device_.dfu_mode();
    const dfu::State st = dfu.state();
    if (st == dfu::State::kAppIdle || st == dfu::State::kAppDetach || st == dfu::State::kManifestWaitReset ||
        static_cast<int>(st) > 10) {
      violated("DFU-mode state outside DFU mode's states");
    }
    if ((st == dfu::State::kError) != (dfu.status() != dfu::Status::kOk)) violated("dfuERROR iff status != OK");
    if (dfu.last_poll_timeout_ms() > 0xFFFFFF) violated("bwPollTimeout beyond 24 bits");
    const auto& cdc = device_.cdc();
    if (cdc.tx_pending() > Device::Cdc::kTxCapacity) violated("CDC ring overflow");
    if (cdc.rx_pending() > 64) violated("CDC rx beyond a packet");
    if (cdc.dropped_reply_bytes() != 0) violated("CDC dropped reply bytes");
    // Sets may arrive incomplete (halt, reset, a lost transfer), but every
    // report the device sends is well-formed and every whole set decodes.
    if (telemetry_.stats().bad_reports != 0 || telemetry_.stats().bad_payloads != 0) {
      violated("HID telemetry report the host decoder refuses");
    }
  }

  // Header written last: a slot whose header reads well-formed holds a
  // payload with that CRC.
  void check_slots() const noexcept {
    if (!nor_.powered()) return;
    for (const DfuTarget& t : kFuzzTargets) {
      const std::span<const std::uint8_t> cells = nor_.contents().subspan(t.region.offset, t.region.size);
      const DfuImageHeader h = decode_dfu_image_header(cells.first<kDfuImageHeaderSize>());
      if (!h.well_formed() || h.length > t.region.size - kDfuImageHeaderSize) continue;
      if (link::crc32(cells.subspan(kDfuImageHeaderSize, h.length)) != h.crc32) violated("valid header, bad payload");
    }
  }

  std::array<std::uint8_t, 8192> cells_{};
  flash::SimulatedNorFlash nor_;
  host::FakeController controller_;
  EchoEndpoint endpoint_;
  NullDetach detach_;
  Device device_;
  TelemetryDecoder<Q> telemetry_;  // the host side of what EP 0x83 sent
};

}  // namespace hadynet::usb::fuzz

#endif  // HADYNET_FUZZ_USB_FUZZ_HARNESS_H_
