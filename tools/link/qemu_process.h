// A QEMU machine running a firmware image, its first serial port on a local
// TCP socket (the link), semihosting on; killed when the object goes.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>
#include <sys/types.h>

#include "tools/link/fd_stream.h"

namespace hadynet::tools {

struct QemuOptions {
  std::string executable = "qemu-system-arm";
  std::string machine = "mps2-an386";  // or netduinoplus2 (STM32F405)
  std::string image;                   // firmware ELF
  bool icount = false;                 // -icount shift=0: 1 instruction = 1 ns of virtual time
  std::string log_file;                // QEMU's stdout/stderr ("" : /dev/null)
  // Raw files placed into the guest's memory before it starts (QEMU's
  // generic loader): e.g. a model slot's contents into the emulated flash.
  struct Load {
    std::string file;
    std::uint32_t address = 0;
  };
  std::vector<Load> loads;
};

// "FILE@ADDRESS" (address decimal or 0x hex, below 2^32) as a load; nullopt
// when it is not of that form.
std::optional<QemuOptions::Load> parse_qemu_load(const std::string& spec);

class QemuProcess {
 public:
  // Starts QEMU (it waits for the link connection before running the guest)
  // and connects. Throws LinkError if QEMU cannot start or connect.
  explicit QemuProcess(const QemuOptions& options, int connect_timeout_ms = 10000);
  ~QemuProcess();
  QemuProcess(const QemuProcess&) = delete;
  QemuProcess& operator=(const QemuProcess&) = delete;

  FdStream& link() { return *link_; }

 private:
  pid_t pid_ = -1;
  std::unique_ptr<FdStream> link_;
};

}  // namespace hadynet::tools
