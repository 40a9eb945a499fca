#include "test/usb_host/cdc_tty_bridge.h"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace hadynet::usb::host_testing {

using host::Handshake;

std::unique_ptr<CdcTtyBridge> CdcTtyBridge::open(std::uint8_t out_ep, std::uint8_t in_ep, std::string& slave_path,
                                                 std::string& error) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) {
    error = std::string("posix_openpt: ") + std::strerror(errno);
    if (master >= 0) ::close(master);
    return nullptr;
  }
  const char* name = ::ptsname(master);
  const int slave = name != nullptr ? ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC) : -1;
  termios tio{};
  if (slave < 0 || ::tcgetattr(slave, &tio) != 0) {
    error = std::string("pty slave: ") + std::strerror(errno);
    ::close(master);
    if (slave >= 0) ::close(slave);
    return nullptr;
  }
  ::cfmakeraw(&tio);  // no echo: the device's replies must not come back to it as input
  ::tcsetattr(slave, TCSANOW, &tio);
  slave_path = name;
  return std::unique_ptr<CdcTtyBridge>(new CdcTtyBridge(master, slave, out_ep, in_ep));
}

CdcTtyBridge::~CdcTtyBridge() { hang_up(); }

void CdcTtyBridge::hang_up() {
  if (master_ >= 0) ::close(master_);
  if (slave_ >= 0) ::close(slave_);
  master_ = slave_ = -1;
}

void CdcTtyBridge::pump(UrbEngine& engine) {
  if (master_ < 0) return;
  host::FakeController& c = engine.device().controller();
  std::uint8_t buffer[512];
  const ssize_t got = ::read(master_, buffer, sizeof buffer);
  if (got > 0) to_device_.insert(to_device_.end(), buffer, buffer + got);
  const std::size_t max_out = c.max_packet(out_ep_);
  while (!to_device_.empty() && c.endpoint_open(out_ep_) && max_out > 0) {
    const std::size_t k = std::min(max_out, to_device_.size());
    if (c.out_token(out_ep_, std::span<const std::uint8_t>(to_device_.data(), k)) != Handshake::kAck) break;
    engine.count(out_ep_);
    to_device_.erase(to_device_.begin(), to_device_.begin() + static_cast<std::ptrdiff_t>(k));
  }
  for (int i = 0; i < 64 && c.endpoint_open(in_ep_); ++i) {
    std::uint8_t packet[64];
    std::size_t n = 0;
    if (c.in_token(in_ep_, packet, n) != Handshake::kAck) break;
    engine.count(in_ep_);
    to_host_.insert(to_host_.end(), packet, packet + n);
  }
  if (!to_host_.empty()) {
    const ssize_t put = ::write(master_, to_host_.data(), to_host_.size());
    if (put > 0) to_host_.erase(to_host_.begin(), to_host_.begin() + put);
  }
}

}  // namespace hadynet::usb::host_testing
