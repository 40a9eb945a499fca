// The host end of DFU 1.1 and ST's DfuSe extension (AN3156), as pure
// protocol code over a control-transfer seam (DfuTransport): libusb in the
// tools (libusb_dfu_transport.h), a simulation in tests. Every wait is
// bounded: the device's bwPollTimeout is honoured through an injected sleep,
// and an operation that stays busy longer than its deadline fails.
#ifndef HADYNET_TOOLS_USB_DFU_CLIENT_H_
#define HADYNET_TOOLS_USB_DFU_CLIENT_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>

#include "firmware/usb/dfu_spec.h"

namespace hadynet::tools::usb {

namespace dfu = hadynet::usb::dfu;

// A failed control transfer, by what the host saw.
class UsbTransferError : public std::runtime_error {
 public:
  enum class Kind { kStall, kGone, kTimeout, kOther };
  UsbTransferError(Kind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

// Class requests to one DFU interface (bmRequestType class | interface).
class DfuTransport {
 public:
  virtual ~DfuTransport() = default;
  // OUT request with `data` as its data stage. Throws UsbTransferError.
  virtual void control_out(std::uint8_t request, std::uint16_t value, std::span<const std::uint8_t> data) = 0;
  // IN request; returns the bytes received (<= buffer.size()). Throws UsbTransferError.
  virtual std::size_t control_in(std::uint8_t request, std::uint16_t value, std::span<std::uint8_t> buffer) = 0;
};

struct DfuStatus {
  dfu::Status status = dfu::Status::kOk;
  std::uint32_t poll_timeout_ms = 0;  // bwPollTimeout
  dfu::State state = dfu::State::kIdle;
  std::uint8_t string_index = 0;      // iString: a string descriptor describing the status (0: none)
};

// The device reported an error status (or an unexpected state).
class DfuError : public std::runtime_error {
 public:
  DfuError(const std::string& what, DfuStatus status) : std::runtime_error(what), status_(status) {}
  const DfuStatus& status() const { return status_; }

 private:
  DfuStatus status_;
};

const char* state_name(dfu::State s);
const char* status_name(dfu::Status s);

class DfuClient {
 public:
  using Sleep = std::function<void(std::uint32_t ms)>;
  // `sleep` waits for bwPollTimeout (tests pass a fake clock).
  // `busy_deadline_ms`: the longest one operation may stay busy in total.
  DfuClient(DfuTransport& transport, Sleep sleep, std::uint32_t busy_deadline_ms = 30000)
      : transport_(transport), sleep_(std::move(sleep)), busy_deadline_ms_(busy_deadline_ms) {}

  DfuStatus get_status();
  dfu::State get_state();
  void clear_status();
  void abort();
  // From any state to dfuIDLE (clears an error, aborts a transfer); throws
  // DfuError if the device will not get there.
  void ensure_idle();

  // One DNLOAD block; then polls GETSTATUS (sleeping bwPollTimeout) until
  // dfuDNLOAD-IDLE. Throws DfuError on an error status.
  void download(std::uint16_t block, std::span<const std::uint8_t> data);
  // One UPLOAD block into `buffer`; the bytes received.
  std::size_t upload(std::uint16_t block, std::span<std::uint8_t> buffer);
  // Plain DFU 1.1: the zero-length DNLOAD that ends a download, then
  // GETSTATUS (sleeping bwPollTimeout) through manifestation until dfuIDLE
  // (a manifestation-tolerant device). Throws DfuError on an error status.
  void manifest();
  // DfuSe "leave": the zero-length DNLOAD that ends a download, then
  // GETSTATUS until the device manifests. A device that resets during manifestation (the
  // DfuSe "leave") may vanish: that is success here.
  void finish_download();

  // DfuSe (block 0 commands, AN3156 §6.1): executed on the GETSTATUS that
  // follows (dfuDNBUSY, then dfuDNLOAD-IDLE).
  void dfuse_set_address(std::uint32_t address);
  void dfuse_erase_sector(std::uint32_t address);

 private:
  void wait_until_idle(const char* what);

  DfuTransport& transport_;
  Sleep sleep_;
  std::uint32_t busy_deadline_ms_;
};

}  // namespace hadynet::tools::usb

#endif  // HADYNET_TOOLS_USB_DFU_CLIENT_H_
