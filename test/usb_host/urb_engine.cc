#include "test/usb_host/urb_engine.h"

#include <linux/usbdevice_fs.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace hadynet::usb::host_testing {

using host::Handshake;

bool UrbEngine::arm(Transfer& t) {
  for (auto f = faults_.begin(); f != faults_.end(); ++f) {
    if (f->ep != t.ep) continue;
    const InjectedFault fault = *f;
    faults_.erase(f);
    switch (fault.kind) {
      case InjectedFault::Kind::kError:
        t.stage = Transfer::Stage::kFinished;  // the device never sees it
        t.status = -fault.error_number;
        return true;
      case InjectedFault::Kind::kShortPacket:
        t.truncate_to = fault.bytes;
        return false;
      case InjectedFault::Kind::kTimeout:
        t.hung = true;
        return false;
    }
  }
  return false;
}

void UrbEngine::truncate(Transfer& t, std::size_t& n) noexcept {
  if (t.truncate_to >= n) return;
  n = t.truncate_to;
  t.truncate_to = static_cast<std::size_t>(-1);
}

bool UrbEngine::advance(Transfer& t) {
  if (t.finished()) return true;
  if (t.hung) return nak();
  if (t.type == USBDEVFS_URB_TYPE_CONTROL) return advance_control(t);
  return is_in(t.ep) ? advance_in(t) : advance_out(t);
}

namespace {
bool finish(Transfer& t, int status) {
  t.status = status;
  t.stage = Transfer::Stage::kFinished;
  return true;
}
}  // namespace

bool UrbEngine::advance_control(Transfer& t) {
  host::FakeController& c = device_.controller();
  const std::uint8_t* s = t.bytes.data();
  const bool in = (s[0] & kRequestDirIn) != 0;
  const std::size_t length = le16(s + 6);
  std::uint8_t packet[kEp0MaxPacket];
  std::size_t n = 0;
  if (t.stage == Transfer::Stage::kSetup) {
    c.setup_raw(std::span<const std::uint8_t, kSetupPacketSize>(t.bytes.first<kSetupPacketSize>()));
    t.stage = length > 0 ? Transfer::Stage::kData : Transfer::Stage::kStatus;
  }
  std::span<std::uint8_t> data = t.bytes.subspan(kSetupPacketSize, length);
  while (t.stage == Transfer::Stage::kData) {
    if (in) {
      const Handshake h = c.in_token(in_endpoint(0), packet, n);
      if (h == Handshake::kNak) return nak();
      if (h == Handshake::kStall) return finish(t, -EPIPE);
      count(in_endpoint(0));
      truncate(t, n);
      if (n > length - t.done) return finish(t, -EOVERFLOW);
      std::memcpy(data.data() + t.done, packet, n);
      t.done += n;
      if (n < kEp0MaxPacket || t.done == length) t.stage = Transfer::Stage::kStatus;
    } else {
      const std::size_t k = std::min(kEp0MaxPacket, length - t.done);
      const Handshake h = c.out_token(out_endpoint(0), data.subspan(t.done, k));
      if (h == Handshake::kNak) return nak();
      if (h == Handshake::kStall) return finish(t, -EPIPE);
      count(out_endpoint(0));
      t.done += k;
      if (t.done == length) t.stage = Transfer::Stage::kStatus;
    }
  }
  // STATUS: the opposite direction, zero length.
  n = 0;
  const Handshake h = in && length > 0 ? c.out_token(out_endpoint(0), {}) : c.in_token(in_endpoint(0), packet, n);
  if (h == Handshake::kNak) return nak();
  if (h == Handshake::kStall) return finish(t, -EPIPE);
  if (n != 0) return finish(t, -EPROTO);  // data in a status stage
  return finish(t, 0);
}

bool UrbEngine::advance_in(Transfer& t) {
  host::FakeController& c = device_.controller();
  const std::size_t max_packet = c.max_packet(t.ep);
  std::uint8_t packet[64];
  while (true) {
    std::size_t n = 0;
    const Handshake h = c.in_token(t.ep, packet, n);
    if (h == Handshake::kNak) return nak();
    if (h == Handshake::kStall) return finish(t, -EPIPE);
    count(t.ep);
    truncate(t, n);
    if (n > t.bytes.size() - t.done) {  // babble: the packet does not fit
      std::memcpy(t.bytes.data() + t.done, packet, t.bytes.size() - t.done);
      t.done = t.bytes.size();
      return finish(t, -EOVERFLOW);
    }
    std::memcpy(t.bytes.data() + t.done, packet, n);
    t.done += n;
    if (n < max_packet) {
      const bool short_not_ok = (t.flags & USBDEVFS_URB_SHORT_NOT_OK) != 0 && t.done < t.bytes.size();
      return finish(t, short_not_ok ? -EREMOTEIO : 0);
    }
    if (t.done == t.bytes.size()) return finish(t, 0);
  }
}

bool UrbEngine::advance_out(Transfer& t) {
  host::FakeController& c = device_.controller();
  const std::size_t max_packet = c.max_packet(t.ep);
  while (true) {
    const std::size_t k = std::min(max_packet, t.bytes.size() - t.done);
    const bool zlp_wanted =
        t.bytes.empty() || ((t.flags & USBDEVFS_URB_ZERO_PACKET) != 0 && t.bytes.size() % max_packet == 0);
    if (k == 0 && (!zlp_wanted || t.zlp_sent)) return finish(t, 0);
    const Handshake h = c.out_token(t.ep, t.bytes.subspan(t.done, k));
    if (h == Handshake::kNak) return nak();
    if (h == Handshake::kStall) return finish(t, -EPIPE);
    count(t.ep);
    t.done += k;
    if (k == 0) t.zlp_sent = true;
    if (k < max_packet && k != 0) return finish(t, 0);  // a short packet ends the transfer
  }
}

int UrbEngine::sync_control(std::uint8_t request_type, std::uint8_t request, std::uint16_t value,
                            std::uint16_t index) {
  std::uint8_t setup[kSetupPacketSize];
  serialize_setup({request_type, request, value, index, 0}, setup);
  Transfer t;
  t.type = USBDEVFS_URB_TYPE_CONTROL;
  t.bytes = setup;
  for (int i = 0; i < kSyncControlRetries; ++i) {
    if (advance(t)) return t.status;
    device_.service();
  }
  return -ETIMEDOUT;
}

std::vector<std::uint8_t> UrbEngine::control_in(std::uint8_t request, std::uint16_t value, std::uint16_t index,
                                                std::uint16_t length, int& status) {
  std::vector<std::uint8_t> bytes(kSetupPacketSize + length);
  serialize_setup({request_type(true, RequestKind::kStandard, Recipient::kDevice), request, value, index, length},
                  std::span<std::uint8_t, kSetupPacketSize>(bytes.data(), kSetupPacketSize));
  Transfer t;
  t.type = USBDEVFS_URB_TYPE_CONTROL;
  t.bytes = bytes;
  status = -ETIMEDOUT;
  for (int i = 0; i < kSyncControlRetries; ++i) {
    if (advance(t)) {
      status = t.status;
      break;
    }
    device_.service();
  }
  return std::vector<std::uint8_t>(bytes.begin() + kSetupPacketSize,
                                   bytes.begin() + static_cast<std::ptrdiff_t>(kSetupPacketSize + t.done));
}

}  // namespace hadynet::usb::host_testing
