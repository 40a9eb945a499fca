#include "tools/link/fd_stream.h"

#include <arpa/inet.h>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <thread>
#include <unistd.h>

namespace hadynet::tools {

namespace {

speed_t baud_constant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    default: return 0;
  }
}

std::string errno_text() { return std::strerror(errno); }

}  // namespace

std::optional<std::pair<std::string, int>> parse_host_port(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) return std::nullopt;
  return std::make_pair(text.substr(0, colon), std::atoi(text.c_str() + colon + 1));
}

FdStream FdStream::open_serial(const std::string& device, int baud) {
  const speed_t speed = baud_constant(baud);
  if (speed == 0) throw LinkError(device + ": unsupported baud rate " + std::to_string(baud));
  const int fd = ::open(device.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) throw LinkError(device + ": cannot open: " + errno_text());
  FdStream s(fd, device);
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) throw LinkError(device + ": not a serial device: " + errno_text());
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | CRTSCTS);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  ::cfsetispeed(&tio, speed);
  ::cfsetospeed(&tio, speed);
  if (::tcsetattr(fd, TCSANOW, &tio) != 0) throw LinkError(device + ": cannot configure: " + errno_text());
  ::tcflush(fd, TCIOFLUSH);
  return s;
}

FdStream FdStream::connect_tcp(const std::string& host, int port, int timeout_ms) {
  const std::string name = host + ":" + std::to_string(port);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0 || found == nullptr)
    throw LinkError(name + ": cannot resolve the host");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  std::string last_error = "timeout";
  while (true) {
    for (addrinfo* a = found; a != nullptr; a = a->ai_next) {
      const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
      if (fd < 0) continue;
      if (::connect(fd, a->ai_addr, a->ai_addrlen) == 0) {
        ::freeaddrinfo(found);
        const int one = 1;
        ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        return FdStream(fd, name);
      }
      last_error = errno_text();
      ::close(fd);
    }
    if (std::chrono::steady_clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::freeaddrinfo(found);
  throw LinkError(name + ": cannot connect: " + last_error);
}

FdStream::FdStream(FdStream&& other) noexcept : fd_(other.fd_), name_(std::move(other.name_)) { other.fd_ = -1; }

FdStream& FdStream::operator=(FdStream&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    name_ = std::move(other.name_);
    other.fd_ = -1;
  }
  return *this;
}

FdStream::~FdStream() {
  if (fd_ >= 0) ::close(fd_);
}

void FdStream::write(std::span<const std::uint8_t> bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      throw LinkError(name_ + ": write failed: " + errno_text());
    }
    done += static_cast<std::size_t>(n);
  }
}

std::size_t FdStream::read(std::span<std::uint8_t> buffer, int timeout_ms) {
  pollfd p{fd_, POLLIN, 0};
  const int ready = ::poll(&p, 1, timeout_ms);
  if (ready < 0) {
    if (errno == EINTR) return 0;
    throw LinkError(name_ + ": poll failed: " + errno_text());
  }
  if (ready == 0) return 0;
  const ssize_t n = ::read(fd_, buffer.data(), buffer.size());
  if (n < 0) {
    if (errno == EINTR || errno == EAGAIN) return 0;
    throw LinkError(name_ + ": read failed: " + errno_text());
  }
  if (n == 0) throw LinkError(name_ + ": the device closed the connection");
  return static_cast<std::size_t>(n);
}

}  // namespace hadynet::tools
