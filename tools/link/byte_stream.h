// A bidirectional byte stream to a device running the firmware: a serial
// port (a USB-UART adapter or a pty) or a TCP socket (QEMU's serial port).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

namespace hadynet::tools {

// I/O failures and timeouts; what() names the device.
class LinkError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ByteStream {
 public:
  virtual ~ByteStream() = default;
  // Writes all bytes or throws LinkError.
  virtual void write(std::span<const std::uint8_t> bytes) = 0;
  // Reads what is available, waiting at most timeout_ms for the first byte;
  // returns 0 on timeout. Throws LinkError on a closed or failed stream.
  virtual std::size_t read(std::span<std::uint8_t> buffer, int timeout_ms) = 0;
  virtual const std::string& name() const = 0;
};

}  // namespace hadynet::tools
