// One device's side of the bus as the umockdev fixture plays it in place of
// the kernel's host controller: a transfer (what one URB asks for) advanced
// packet by packet through the device's FakeController, and the faults a
// test injects into the next transfer on an endpoint. No umockdev types here
// (usbdevfs_node.h queues the URBs); the caller holds the bus lock.
//
// Transfer rules (the kernel's, as far as a full-speed device shows them):
//   control → SETUP, DATA and STATUS stages one packet at a time;
//   bulk/interrupt OUT → one out_token per max-packet packet (+ a ZLP when
//   USBDEVFS_URB_ZERO_PACKET asks and the last packet was full);
//   bulk/interrupt IN → in_token until a short packet or the buffer is full
//   (a packet larger than the room left: -EOVERFLOW). NAK keeps the transfer
//   where it stopped; STALL finishes it with -EPIPE.
#ifndef HADYNET_TEST_USB_HOST_URB_ENGINE_H_
#define HADYNET_TEST_USB_HOST_URB_ENGINE_H_

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "firmware/usb/usb_spec.h"
#include "test/usb_host/emulated_device.h"

namespace hadynet::usb::host_testing {

// One transfer in progress on the bus: where it stopped and how it ended.
// `bytes` is the URB buffer (control: 8-byte SETUP + data stage).
struct Transfer {
  enum class Stage : std::uint8_t { kSetup, kData, kStatus, kFinished };
  std::uint8_t type = 0;  // USBDEVFS_URB_TYPE_*
  EndpointAddress ep = 0;
  unsigned flags = 0;  // USBDEVFS_URB_*
  std::span<std::uint8_t> bytes;
  std::size_t done = 0;  // data bytes moved (control: of the data stage)
  Stage stage = Stage::kSetup;
  bool zlp_sent = false;
  int status = 0;  // when finished: 0 or -errno
  // Injected faults (armed at submission, see UrbEngine::arm).
  bool hung = false;                              // never advances: completes only when discarded
  std::size_t truncate_to = static_cast<std::size_t>(-1);  // the next ACKed IN packet is cut to this many bytes
  bool finished() const noexcept { return stage == Stage::kFinished; }
};

// A fault for the next client transfer on one endpoint (0x00: control).
struct InjectedFault {
  enum class Kind : std::uint8_t {
    kError,        // finishes with -error_number before reaching the device (EPIPE looks like a STALL)
    kShortPacket,  // the device's next IN packet reaches the host cut to `bytes` (a short packet)
    kTimeout,      // the transfer never completes (no handshake) until the client discards it
  };
  EndpointAddress ep = 0;
  Kind kind = Kind::kError;
  int error_number = 0;
  std::size_t bytes = 0;
};

// Per-endpoint packet counts (index: endpoint number + 16 for IN).
struct PacketCounts {
  std::uint64_t acked[32] = {};
  std::uint64_t of(EndpointAddress ep) const noexcept { return acked[(ep & 0x0F) + (is_in(ep) ? 16 : 0)]; }
};

class UrbEngine {
 public:
  explicit UrbEngine(EmulatedDevice& device) noexcept : device_(device) {}

  // Advances `t` as far as the device lets it; true when finished.
  bool advance(Transfer& t);
  // Applies (and forgets) the first fault queued for `t.ep` to a newly
  // submitted transfer; true if it finished it at once (kError).
  bool arm(Transfer& t);
  void add_fault(const InjectedFault& f) { faults_.push_back(f); }

  // A control request the kernel sends itself (SET_ADDRESS,
  // SET_CONFIGURATION, ...): retried after service() while NAKed; 0 or -errno
  // (-ETIMEDOUT after kSyncControlRetries).
  int sync_control(std::uint8_t request_type, std::uint8_t request, std::uint16_t value, std::uint16_t index);
  // A standard device-to-host request on EP0 (enumeration); the data stage
  // read, `status` 0 or -errno.
  std::vector<std::uint8_t> control_in(std::uint8_t request, std::uint16_t value, std::uint16_t index,
                                       std::uint16_t length, int& status);

  std::uint64_t naks() const noexcept { return naks_; }
  // Counts an ACKed data packet moved outside a transfer (the tty bridge).
  void count(EndpointAddress ep) noexcept { ++packets_.acked[(ep & 0x0F) + (is_in(ep) ? 16 : 0)]; }
  const PacketCounts& packets() const noexcept { return packets_; }
  EmulatedDevice& device() noexcept { return device_; }

  // Retries of a synchronous control request the device NAKs, each after one
  // service(); the kernel's 5 s USB_CTRL_SET_TIMEOUT is far longer, but a
  // device that NAKs this often here is broken.
  static constexpr int kSyncControlRetries = 1000;

 private:
  bool advance_control(Transfer& t);
  bool advance_in(Transfer& t);
  bool advance_out(Transfer& t);
  bool nak() noexcept {
    ++naks_;
    return false;
  }
  // Cuts an ACKed IN packet of `n` bytes as an armed short-packet fault says.
  void truncate(Transfer& t, std::size_t& n) noexcept;

  EmulatedDevice& device_;
  std::vector<InjectedFault> faults_;
  std::uint64_t naks_ = 0;
  PacketCounts packets_;
};

inline std::uint16_t le16(const std::uint8_t* p) noexcept { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_USB_HOST_URB_ENGINE_H_
