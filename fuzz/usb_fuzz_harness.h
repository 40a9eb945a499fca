// The USB device stack under arbitrary host behaviour: SETUP packets (raw and
// class requests aimed at the DFU and CDC interfaces), IN/OUT tokens with any
// data on any endpoint, bus resets, suspend/resume, service() calls,
// telemetry records, flash faults (power cut, write error) of the simulated
// NOR flash, and resets of the whole device (RAM lost, the boot rule runs
// over the same flash). The DFU model interface streams images into a
// ModelSlots over a small flash (two 2 KiB slots, a 700-byte model). After
// every event the stack's and the slots' invariants are checked; a
// violation aborts (libFuzzer reports it).
//
// Input: records, each an opcode byte (UsbFuzzOp, modulo kCount) and its
// arguments; a truncated record ends the input.
#ifndef HADYNET_FUZZ_USB_FUZZ_HARNESS_H_
#define HADYNET_FUZZ_USB_FUZZ_HARNESS_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <span>

#include "firmware/app/period_record.h"
#include "firmware/crypto/sha256.h"
#include "firmware/flash/simulated_nor_flash.h"
#include "firmware/model_update/image_check.h"
#include "firmware/model_update/model_slots.h"
#include "firmware/model_update/slot_layout.h"
#include "firmware/usb/hadynet_usb_device.h"
#include "firmware/usb/host/fake_controller.h"
#include "firmware/usb/telemetry_decoder.h"
#include "fuzz/usb_fuzz_model.h"
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
  kReset = 12,       // verdict byte (bit 0: the self-test passes): power on, new device and slots, boot rule
  kCount = 13,
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

struct VerdictSelfTest final : model_update::SelfTest {
  bool run(std::span<const std::uint8_t>, const model_update::ModelImageHeader&) noexcept override { return pass; }
  bool pass = true;
};

[[noreturn]] inline void violated(const char* what) noexcept {
  (void)what;  // visible in the debugger / stack trace
  std::abort();
}

class UsbFuzzHarness {
 public:
  using Device = HadynetUsbDevice<Q, EchoEndpoint, EchoEndpoint::kMaxReply>;

  UsbFuzzHarness() noexcept : nor_(kFuzzSectors, cells_) { power_on_reset(true); }

  const Device& device() const noexcept { return *device_; }
  const model_update::ModelSlots& slots() const noexcept { return *slots_; }
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
          controller_->bus_reset();
          break;
        case UsbFuzzOp::kSetupRaw:
          if (!take(8, a)) return;
          controller_->setup_raw(a.first<8>());
          break;
        case UsbFuzzOp::kInToken: {
          if (!take(1, a)) return;
          std::uint8_t packet[64];
          std::size_t n = 0;
          const EndpointAddress ep = static_cast<EndpointAddress>(a[0] & 0x8F);
          if (controller_->in_token(ep, packet, n) == host::Handshake::kAck && ep == composite::kHidReportIn) {
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
          controller_->out_token(ep, d);
          break;
        }
        case UsbFuzzOp::kService:
          device_->service();
          break;
        case UsbFuzzOp::kPublish: {
          if (!take(1, a)) return;
          app::PeriodRecord<Q> r;
          r.sequence = a[0];
          r.period = a[0];
          r.flags = static_cast<std::uint16_t>(a[0] & app::kRecordKnownFlags);
          device_->publish(r);
          break;
        }
        case UsbFuzzOp::kSuspendResume:
          if (!take(1, a)) return;
          if (a[0] & 1) {
            controller_->suspend();
          } else {
            controller_->resume();
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
          controller_->control(s, d, reply);
          break;
        }
        case UsbFuzzOp::kEnumerate:
          controller_->bus_reset();
          controller_->control({0x00, request::kSetAddress, 7, 0, 0}, {}, {});
          controller_->control({0x00, request::kSetConfiguration, 1, 0, 0}, {}, {});
          break;
        case UsbFuzzOp::kSpuriousCompletion:
          if (!take(2, a)) return;
          controller_->inject(ControllerEvent::transfer_complete(static_cast<EndpointAddress>(a[0] & 0x8F), a[1]));
          break;
        case UsbFuzzOp::kReset:
          if (!take(1, a)) return;
          power_on_reset((a[0] & 1) != 0);
          break;
        case UsbFuzzOp::kCount:
          break;
      }
      check_invariants();
      check_slots();
    }
  }

 private:
  static constexpr std::array<std::uint8_t, kUniqueIdBytes> kUid = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};

  // A power-on reset: RAM lost (new controller, device and ModelSlots), the
  // flash cells kept, the boot rule run before the device is built.
  void power_on_reset(bool self_test_passes) noexcept {
    device_.reset();
    slots_.reset();
    controller_.reset();
    nor_.power_on();
    controller_.emplace();
    slots_.emplace(nor_, kFuzzSlotA, kFuzzSlotB, fuzz_identity(), kFuzzPublicKey, nor_.contents());
    self_test_.pass = self_test_passes;
    slots_->boot(self_test_);
    boot_choice_ = slots_->choice();
    running_image_ = {};
    if (boot_choice_.source != model_update::ModelSource::kFactory) {
      const std::span<const std::uint8_t> slot = slot_cells(running_slot());
      for (std::size_t i = 0; i < model_update::kImageHeaderSize; ++i) running_image_[i] = slot[i];
      for (std::size_t i = 0; i < kFuzzPayloadBytes; ++i) {
        running_image_[model_update::kImageHeaderSize + i] = slot[model_update::kSlotPayloadOffset + i];
      }
    }
    header_seen_ = {};
    header_checked_ = {};
    device_.emplace(*controller_, endpoint_, ModelSlotsAccess{&*slots_, &nor_}, detach_, kUid, "fuzz");
    device_->start();
  }

  model_update::SlotId running_slot() const noexcept {
    return boot_choice_.source == model_update::ModelSource::kSlotA ? model_update::SlotId::kA
                                                                    : model_update::SlotId::kB;
  }
  std::span<const std::uint8_t> slot_cells(model_update::SlotId s) const noexcept {
    const flash::FlashRegion& r = s == model_update::SlotId::kA ? kFuzzSlotA : kFuzzSlotB;
    return nor_.contents().subspan(r.offset, r.size);
  }

  void check_invariants() const noexcept {
    const UsbDevice& d = device_->device();
    if (d.address() > 127) violated("address > 127");
    if (static_cast<int>(d.state()) > 2) violated("device state");
    if (static_cast<int>(d.control_stage()) > 5) violated("control stage");
    static constexpr EndpointAddress kEndpoints[] = {0x81, 0x02, 0x82, 0x83};
    if (d.state() == DeviceState::kConfigured) {
      for (const EndpointAddress ep : kEndpoints) {
        if (!controller_->endpoint_open(ep)) violated("configured with a closed endpoint");
      }
    } else {
      for (const EndpointAddress ep : kEndpoints) {
        if (controller_->transfer_active(ep)) violated("transfer on an endpoint of no configuration");
      }
    }
    const DfuMode& dfu = device_->dfu_mode();
    const dfu::State st = dfu.state();
    if (st == dfu::State::kAppIdle || st == dfu::State::kAppDetach || st == dfu::State::kManifestWaitReset ||
        static_cast<int>(st) > 10) {
      violated("DFU-mode state outside DFU mode's states");
    }
    if ((st == dfu::State::kError) != (dfu.status() != dfu::Status::kOk)) violated("dfuERROR iff status != OK");
    if (st == dfu::State::kError && dfu.status_text()[0] == '\0') violated("a DFU error without a description");
    if (dfu.last_poll_timeout_ms() > 0xFFFFFF) violated("bwPollTimeout beyond 24 bits");
    // An update lives only inside a download: every other state ended it.
    const bool downloading = st == dfu::State::kDnloadSync || st == dfu::State::kDnBusy ||
                             st == dfu::State::kDnloadIdle || st == dfu::State::kManifestSync ||
                             st == dfu::State::kManifest;
    if (slots_->update_in_progress() && !downloading) violated("a ModelSlots update outside a DFU download");
    const auto& cdc = device_->cdc();
    if (cdc.tx_pending() > Device::Cdc::kTxCapacity) violated("CDC ring overflow");
    if (cdc.rx_pending() > 64) violated("CDC rx beyond a packet");
    if (cdc.dropped_reply_bytes() != 0) violated("CDC dropped reply bytes");
    // Sets may arrive incomplete (halt, reset, a lost transfer), but every
    // report the device sends is well-formed and every whole set decodes.
    if (telemetry_.stats().bad_reports != 0 || telemetry_.stats().bad_payloads != 0) {
      violated("HID telemetry report the host decoder refuses");
    }
  }

  // The slots, whatever the host and the flash did:
  //   * a slot whose header checks out (well-formed, this firmware's
  //     identity, the trusted key, a valid signature) holds a payload whose
  //     SHA-256 is the header's (the header is programmed last);
  //   * the boot choice does not change until the next reset, and the image
  //     in use (its header and payload; not its trial flags, which a forced
  //     downgrade may set) is never written: no update targets its slot.
  void check_slots() noexcept {
    if (slots_->choice().source != boot_choice_.source || slots_->choice().sequence != boot_choice_.sequence) {
      violated("the boot choice changed without a reset");
    }
    if (boot_choice_.source != model_update::ModelSource::kFactory) {
      const std::span<const std::uint8_t> slot = slot_cells(running_slot());
      for (std::size_t i = 0; i < model_update::kImageHeaderSize; ++i) {
        if (slot[i] != running_image_[i]) violated("the running image's header was written");
      }
      for (std::size_t i = 0; i < kFuzzPayloadBytes; ++i) {
        if (slot[model_update::kSlotPayloadOffset + i] != running_image_[model_update::kImageHeaderSize + i]) {
          violated("the running image's payload was written");
        }
      }
      if (slots_->update_in_progress() && slots_->update_target() == running_slot()) {
        violated("an update into the slot in use");
      }
    }
    for (const model_update::SlotId s : {model_update::SlotId::kA, model_update::SlotId::kB}) {
      const std::span<const std::uint8_t> slot = slot_cells(s);
      const std::span<const std::uint8_t, model_update::kImageHeaderSize> header =
          slot.first<model_update::kImageHeaderSize>();
      const std::size_t i = model_update::slot_index(s);
      bool same = true;
      for (std::size_t k = 0; k < header.size(); ++k) same = same && header[k] == header_seen_[i][k];
      if (!same) {  // the signature check only when the header's bytes changed
        for (std::size_t k = 0; k < header.size(); ++k) header_seen_[i][k] = header[k];
        model_update::ModelImageHeader decoded;
        const flash::FlashRegion& r = s == model_update::SlotId::kA ? kFuzzSlotA : kFuzzSlotB;
        header_checked_[i] = model_update::check_image_header(header, fuzz_identity(), kFuzzPublicKey, r.size,
                                                              decoded) == model_update::UpdateError::kOk;
        payload_sha_[i] = decoded.payload_sha256;
      }
      if (!header_checked_[i]) continue;
      const std::array<std::uint8_t, crypto::kSha256Bytes> sha =
          crypto::sha256(slot.subspan(model_update::kSlotPayloadOffset, kFuzzPayloadBytes));
      if (sha != payload_sha_[i]) violated("a slot whose header checks out holds another payload");
    }
  }

  std::array<std::uint8_t, kFuzzFlashBytes> cells_{};
  flash::SimulatedNorFlash nor_;
  std::optional<host::FakeController> controller_;
  std::optional<model_update::ModelSlots> slots_;
  VerdictSelfTest self_test_;
  EchoEndpoint endpoint_;
  NullDetach detach_;
  std::optional<Device> device_;
  TelemetryDecoder<Q> telemetry_;  // the host side of what EP 0x83 sent

  model_update::BootChoice boot_choice_{};
  std::array<std::uint8_t, model_update::kImageHeaderSize + kFuzzPayloadBytes> running_image_{};
  std::array<std::array<std::uint8_t, model_update::kImageHeaderSize>, model_update::kSlotCount> header_seen_{};
  std::array<bool, model_update::kSlotCount> header_checked_{};
  std::array<std::array<std::uint8_t, crypto::kSha256Bytes>, model_update::kSlotCount> payload_sha_{};
};

}  // namespace hadynet::usb::fuzz

#endif  // HADYNET_FUZZ_USB_FUZZ_HARNESS_H_
