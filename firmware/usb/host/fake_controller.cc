#include "firmware/usb/host/fake_controller.h"

namespace hadynet::usb::host {

void FakeController::record(ControllerCall::Kind kind, EndpointAddress ep, std::uint32_t value) noexcept {
  log_[calls_ % kLogSize] = ControllerCall{kind, ep, value};
  ++calls_;
}

std::size_t FakeController::count(ControllerCall::Kind kind) const noexcept {
  std::size_t n = 0;
  for (std::size_t i = 0; i < logged(); ++i) n += call(i).kind == kind ? 1 : 0;
  return n;
}

const ControllerCall& FakeController::call(std::size_t i) const noexcept {
  const std::size_t first = calls_ < kLogSize ? 0 : calls_ - kLogSize;
  return log_[(first + i) % kLogSize];
}

void FakeController::reset_endpoints() noexcept {
  for (Endpoint& e : endpoints_) e = Endpoint{};
  for (const EndpointAddress ep0 : {out_endpoint(0), in_endpoint(0)}) {
    Endpoint& e = state(ep0);
    e.open = true;
    e.type = EndpointType::kControl;
    e.max_packet = static_cast<std::uint16_t>(kEp0MaxPacket);
  }
  ep0_stalled_ = false;
}

void FakeController::deliver(const ControllerEvent& event) noexcept {
  if (handler_ != nullptr) handler_->handle(event);
}

void FakeController::init(ControllerEventHandler& handler) noexcept {
  record(ControllerCall::Kind::kInit, 0, 0);
  handler_ = &handler;
  connected_ = false;
  address_ = 0;
  reset_endpoints();
}

void FakeController::set_connected(bool connected) noexcept {
  record(ControllerCall::Kind::kSetConnected, 0, connected ? 1 : 0);
  connected_ = connected;
}

void FakeController::set_address(std::uint8_t address) noexcept {
  record(ControllerCall::Kind::kSetAddress, 0, address);
  address_ = address;  // like OTG FS DCFG.DAD: the status stage still completes
}

bool FakeController::open_endpoint(const EndpointConfig& config) noexcept {
  record(ControllerCall::Kind::kOpenEndpoint, config.address, config.max_packet);
  const std::uint8_t number = endpoint_number(config.address);
  if (!valid(config.address) || number == 0 || config.max_packet == 0 || config.max_packet > 64 ||
      config.type == EndpointType::kControl || config.type == EndpointType::kIsochronous) {
    return false;
  }
  Endpoint& e = state(config.address);
  e = Endpoint{};
  e.open = true;
  e.type = config.type;
  e.max_packet = config.max_packet;
  return true;
}

void FakeController::close_endpoint(EndpointAddress ep) noexcept {
  record(ControllerCall::Kind::kCloseEndpoint, ep, 0);
  if (!valid(ep) || endpoint_number(ep) == 0) return;
  state(ep) = Endpoint{};
}

bool FakeController::start_transfer(EndpointAddress ep, std::span<std::uint8_t> buffer) noexcept {
  record(ControllerCall::Kind::kStartTransfer, ep, static_cast<std::uint32_t>(buffer.size()));
  if (!valid(ep)) return false;
  Endpoint& e = state(ep);
  if (!e.open || e.halted || e.active) return false;
  if (!is_in(ep) && endpoint_number(ep) != 0 && buffer.size() % e.max_packet != 0) return false;
  e.active = true;
  e.buffer = buffer;
  e.done = 0;
  return true;
}

void FakeController::stall_control() noexcept {
  record(ControllerCall::Kind::kStallControl, 0, 0);
  ep0_stalled_ = true;
  state(in_endpoint(0)).active = false;
  state(out_endpoint(0)).active = false;
}

void FakeController::set_endpoint_halt(EndpointAddress ep, bool halted) noexcept {
  record(ControllerCall::Kind::kSetHalt, ep, halted ? 1 : 0);
  if (!valid(ep) || endpoint_number(ep) == 0) return;
  Endpoint& e = state(ep);
  e.halted = halted;
  e.active = false;  // the seam: the active transfer is dropped either way
}

void FakeController::bus_reset() noexcept {
  address_ = 0;
  reset_endpoints();
  deliver(ControllerEvent::bus_reset());
}

void FakeController::suspend() noexcept { deliver(ControllerEvent::suspend()); }
void FakeController::resume() noexcept { deliver(ControllerEvent::resume()); }

void FakeController::setup(const SetupPacket& setup) noexcept {
  std::array<std::uint8_t, kSetupPacketSize> bytes{};
  serialize_setup(setup, bytes);
  setup_raw(bytes);
}

void FakeController::setup_raw(std::span<const std::uint8_t, kSetupPacketSize> bytes) noexcept {
  ep0_stalled_ = false;
  state(in_endpoint(0)).active = false;
  state(out_endpoint(0)).active = false;
  deliver(ControllerEvent::setup_packet(bytes));
}

Handshake FakeController::in_token(EndpointAddress ep, std::span<std::uint8_t> out, std::size_t& size) noexcept {
  size = 0;
  if (!valid(ep) || !is_in(ep)) return Handshake::kStall;
  Endpoint& e = state(ep);
  if (endpoint_number(ep) == 0 ? ep0_stalled_ : (e.halted || !e.open)) return Handshake::kStall;
  if (!e.active) return Handshake::kNak;
  const std::size_t left = e.buffer.size() - e.done;
  const std::size_t n = left < e.max_packet ? left : e.max_packet;
  for (std::size_t i = 0; i < n && i < out.size(); ++i) out[i] = e.buffer[e.done + i];
  size = n < out.size() ? n : out.size();
  e.done += n;
  if (e.done == e.buffer.size()) {  // the last packet (short, or exactly the end)
    e.active = false;
    deliver(ControllerEvent::transfer_complete(ep, static_cast<std::uint16_t>(e.done)));
  }
  return Handshake::kAck;
}

Handshake FakeController::out_token(EndpointAddress ep, std::span<const std::uint8_t> packet) noexcept {
  if (!valid(ep) || is_in(ep)) return Handshake::kStall;
  Endpoint& e = state(ep);
  if (endpoint_number(ep) == 0 ? ep0_stalled_ : (e.halted || !e.open)) return Handshake::kStall;
  if (!e.active) return Handshake::kNak;
  if (packet.size() > e.max_packet || packet.size() > e.buffer.size() - e.done) {
    ++babble_;
    return Handshake::kNak;
  }
  for (std::size_t i = 0; i < packet.size(); ++i) e.buffer[e.done + i] = packet[i];
  e.done += packet.size();
  if (packet.size() < e.max_packet || e.done == e.buffer.size()) {
    e.active = false;
    deliver(ControllerEvent::transfer_complete(ep, static_cast<std::uint16_t>(e.done)));
  }
  return Handshake::kAck;
}

ControlResult FakeController::control(const SetupPacket& s, std::span<const std::uint8_t> out,
                                       std::span<std::uint8_t> in) noexcept {
  ControlResult r;
  const auto stop = [&r](Handshake h, ControlResult::Stage stage) {
    r.outcome = h == Handshake::kStall ? ControlResult::Outcome::kStall : ControlResult::Outcome::kNak;
    r.stage = stage;
    return r;
  };
  setup(s);
  std::uint8_t packet[kEp0MaxPacket] = {};
  std::size_t n = 0;
  if (s.length > 0 && s.is_in()) {
    const std::size_t want = s.length;
    std::size_t got = 0;  // bytes of the data stage, also those beyond `in`
    while (true) {
      const Handshake h = in_token(in_endpoint(0), packet, n);
      if (h != Handshake::kAck) return stop(h, ControlResult::Stage::kData);
      for (std::size_t i = 0; i < n && r.in_bytes < in.size(); ++i) in[r.in_bytes++] = packet[i];
      got += n;
      if (n < kEp0MaxPacket || got >= want) break;
    }
    const Handshake h = out_token(out_endpoint(0), {});
    if (h != Handshake::kAck) return stop(h, ControlResult::Stage::kStatus);
    return r;
  }
  if (s.length > 0) {
    const std::size_t total = out.size() < s.length ? out.size() : s.length;
    std::size_t sent = 0;
    do {
      const std::size_t k = total - sent < kEp0MaxPacket ? total - sent : kEp0MaxPacket;
      const Handshake h = out_token(out_endpoint(0), out.subspan(sent, k));
      if (h != Handshake::kAck) return stop(h, ControlResult::Stage::kData);
      sent += k;
      if (k < kEp0MaxPacket) break;
    } while (sent < total);
    if (sent == total && total < s.length && total > 0 && total % kEp0MaxPacket == 0) {
      const Handshake h = out_token(out_endpoint(0), {});  // ends a data stage shorter than wLength
      if (h != Handshake::kAck) return stop(h, ControlResult::Stage::kData);
    }
  }
  const Handshake h = in_token(in_endpoint(0), packet, n);
  if (h != Handshake::kAck) return stop(h, ControlResult::Stage::kStatus);
  if (n != 0) {  // a status stage carries no data
    r.outcome = ControlResult::Outcome::kStall;
    r.stage = ControlResult::Stage::kStatus;
  }
  return r;
}

}  // namespace hadynet::usb::host
