// ByteStream over a POSIX file descriptor: a serial port in raw mode or a
// connected TCP socket.
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "tools/link/byte_stream.h"

namespace hadynet::tools {

// "HOST:PORT" split at its last colon (so "[::1]:4000"-style hosts keep
// theirs); nullopt if there is no colon or no host.
std::optional<std::pair<std::string, int>> parse_host_port(const std::string& text);

class FdStream : public ByteStream {
 public:
  // Opens a serial device (or a pty) in raw 8N1 mode at `baud` (one of the
  // standard rates). Throws LinkError naming the device.
  static FdStream open_serial(const std::string& device, int baud);
  // Connects to host:port, retrying until `timeout_ms` passes (a QEMU that
  // is still starting). Throws LinkError.
  static FdStream connect_tcp(const std::string& host, int port, int timeout_ms);

  FdStream(FdStream&& other) noexcept;
  FdStream& operator=(FdStream&& other) noexcept;
  FdStream(const FdStream&) = delete;
  FdStream& operator=(const FdStream&) = delete;
  ~FdStream() override;

  void write(std::span<const std::uint8_t> bytes) override;
  std::size_t read(std::span<std::uint8_t> buffer, int timeout_ms) override;
  const std::string& name() const override { return name_; }

 private:
  FdStream(int fd, std::string name) : fd_(fd), name_(std::move(name)) {}
  int fd_ = -1;
  std::string name_;
};

}  // namespace hadynet::tools
