// The host backend of the device-controller seam: a scripted fake controller
// for tests, the fuzzer and (later) a umockdev fixture that serves the device
// to libusb. Device side: it implements DeviceController and records every
// call. Host side: it plays the host controller, one transaction at a time
// (SETUP, IN token, OUT token, bus reset, suspend/resume), delivering the
// events the seam defines to the stack synchronously, and reports each
// token's handshake (ACK with data, NAK, STALL). control() runs a whole
// control transfer. Allocation-free like the stack.
#ifndef HADYNET_FIRMWARE_USB_HOST_FAKE_CONTROLLER_H_
#define HADYNET_FIRMWARE_USB_HOST_FAKE_CONTROLLER_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/usb/device_controller.h"
#include "firmware/usb/usb_spec.h"

namespace hadynet::usb::host {

enum class Handshake : std::uint8_t { kAck, kNak, kStall };

// One recorded call of the stack into the controller.
struct ControllerCall {
  enum class Kind : std::uint8_t {
    kInit,
    kSetConnected,
    kSetAddress,
    kOpenEndpoint,
    kCloseEndpoint,
    kStartTransfer,
    kStallControl,
    kSetHalt,
  };
  Kind kind = Kind::kInit;
  EndpointAddress endpoint = 0;
  std::uint32_t value = 0;  // connected / address / max packet / transfer bytes / halted
};

struct ControlResult {
  enum class Outcome : std::uint8_t { kOk, kStall, kNak };
  enum class Stage : std::uint8_t { kSetup, kData, kStatus };
  Outcome outcome = Outcome::kOk;
  Stage stage = Stage::kSetup;  // where a STALL or NAK happened
  std::size_t in_bytes = 0;     // data stage bytes received (IN requests)

  bool ok() const noexcept { return outcome == Outcome::kOk; }
  bool stalled() const noexcept { return outcome == Outcome::kStall; }
};

class FakeController final : public DeviceController {
 public:
  static constexpr std::size_t kEndpoints = 2 * (kMaxEndpointNumber + 1);
  static constexpr std::size_t kLogSize = 512;

  // ---- DeviceController (the stack calls these) ----
  void init(ControllerEventHandler& handler) noexcept override;
  void set_connected(bool connected) noexcept override;
  void set_address(std::uint8_t address) noexcept override;
  bool open_endpoint(const EndpointConfig& config) noexcept override;
  void close_endpoint(EndpointAddress ep) noexcept override;
  bool start_transfer(EndpointAddress ep, std::span<std::uint8_t> buffer) noexcept override;
  void stall_control() noexcept override;
  void set_endpoint_halt(EndpointAddress ep, bool halted) noexcept override;

  // ---- the host's side ----
  void bus_reset() noexcept;
  void suspend() noexcept;
  void resume() noexcept;
  // A SETUP packet on EP0 (cancels EP0 transfers, clears the EP0 stall).
  void setup(const SetupPacket& setup) noexcept;
  void setup_raw(std::span<const std::uint8_t, kSetupPacketSize> bytes) noexcept;
  // An IN token: on ACK, one packet (<= max packet) is copied to `out` and
  // its size stored in `size`.
  Handshake in_token(EndpointAddress ep, std::span<std::uint8_t> out, std::size_t& size) noexcept;
  // An OUT token with one packet (<= max packet bytes).
  Handshake out_token(EndpointAddress ep, std::span<const std::uint8_t> packet) noexcept;
  // A whole control transfer: SETUP, data stage (`out` for OUT requests,
  // min(wLength, in.size()) into `in` for IN requests), status stage.
  ControlResult control(const SetupPacket& setup, std::span<const std::uint8_t> out,
                        std::span<std::uint8_t> in) noexcept;
  // Delivers any event as it is, outside the seam's contract too (e.g. a
  // completion on an endpoint without a transfer): robustness tests.
  void inject(const ControllerEvent& event) noexcept { deliver(event); }

  // ---- observations ----
  bool initialised() const noexcept { return handler_ != nullptr; }
  bool connected() const noexcept { return connected_; }
  std::uint8_t address() const noexcept { return address_; }
  bool control_stalled() const noexcept { return ep0_stalled_; }
  bool endpoint_open(EndpointAddress ep) const noexcept { return state(ep).open; }
  bool endpoint_halted(EndpointAddress ep) const noexcept { return state(ep).halted; }
  bool transfer_active(EndpointAddress ep) const noexcept { return state(ep).active; }
  std::uint16_t max_packet(EndpointAddress ep) const noexcept { return state(ep).max_packet; }
  EndpointType endpoint_type(EndpointAddress ep) const noexcept { return state(ep).type; }
  std::size_t call_count() const noexcept { return calls_; }
  std::size_t count(ControllerCall::Kind kind) const noexcept;
  // The i-th recorded call (0 = oldest kept); the log keeps the last kLogSize.
  const ControllerCall& call(std::size_t i) const noexcept;
  std::size_t logged() const noexcept { return calls_ < kLogSize ? calls_ : kLogSize; }
  // Protocol errors of the host side: an OUT packet larger than max packet
  // or than the room left in the armed buffer (a real controller: babble).
  std::size_t babble_errors() const noexcept { return babble_; }

 private:
  struct Endpoint {
    bool open = false;
    bool halted = false;
    bool active = false;
    EndpointType type = EndpointType::kControl;
    std::uint16_t max_packet = 0;
    std::span<std::uint8_t> buffer{};
    std::size_t done = 0;  // bytes sent / received so far
  };
  static std::size_t index(EndpointAddress ep) noexcept {
    return static_cast<std::size_t>(endpoint_number(ep) & kMaxEndpointNumber) * 2 + (is_in(ep) ? 1 : 0);
  }
  Endpoint& state(EndpointAddress ep) noexcept { return endpoints_[index(ep)]; }
  const Endpoint& state(EndpointAddress ep) const noexcept { return endpoints_[index(ep)]; }
  bool valid(EndpointAddress ep) const noexcept {
    return endpoint_number(ep) <= kMaxEndpointNumber && (ep & 0x70) == 0;
  }
  void record(ControllerCall::Kind kind, EndpointAddress ep, std::uint32_t value) noexcept;
  void reset_endpoints() noexcept;
  void deliver(const ControllerEvent& event) noexcept;

  ControllerEventHandler* handler_ = nullptr;
  bool connected_ = false;
  std::uint8_t address_ = 0;
  bool ep0_stalled_ = false;
  std::array<Endpoint, kEndpoints> endpoints_{};
  std::array<ControllerCall, kLogSize> log_{};
  std::size_t calls_ = 0;
  std::size_t babble_ = 0;
};

}  // namespace hadynet::usb::host

#endif  // HADYNET_FIRMWARE_USB_HOST_FAKE_CONTROLLER_H_
