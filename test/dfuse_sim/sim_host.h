// The host's side of the simulated ROM bootloader in tests: enumeration,
// DFU class requests as whole control transfers on the FakeController, and
// SimDfuTransport, the DfuTransport (tools/usb/dfu_client.h) the host
// flasher runs on in-process (a STALL -> UsbTransferError kStall, a device
// that left the bus -> kGone), with a fake sleep that only counts.
#ifndef HADYNET_TEST_DFUSE_SIM_SIM_HOST_H_
#define HADYNET_TEST_DFUSE_SIM_SIM_HOST_H_

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "firmware/usb/host/fake_controller.h"
#include "test/dfuse_sim/stm32_rom_bootloader.h"
#include "test/usb/test_bytes.h"
#include "tools/usb/dfu_client.h"

namespace hadynet::usb::host_testing {

using test_data::Bytes;
using test_data::pseudo_random;

inline SetupPacket standard_out(std::uint8_t request, std::uint16_t value, std::uint16_t index = 0) {
  return {request_type(false, RequestKind::kStandard, Recipient::kDevice), request, value, index, 0};
}
inline SetupPacket get_descriptor(std::uint8_t type, std::uint8_t index, std::uint16_t length,
                                  std::uint16_t language = 0) {
  return {request_type(true, RequestKind::kStandard, Recipient::kDevice), request::kGetDescriptor,
          static_cast<std::uint16_t>((type << 8) | index), language, length};
}
inline SetupPacket dfu_request(bool in, std::uint8_t request, std::uint16_t value, std::uint16_t length) {
  return {request_type(in, RequestKind::kClass, Recipient::kInterface), request, value, kRomDfuInterface, length};
}

// Bus reset, SET_ADDRESS(7), SET_CONFIGURATION(1), SET_INTERFACE(0, alt):
// what a host (and dfu-util -a) does. true on success.
inline bool enumerate(host::FakeController& c, std::uint8_t alternate = 0) {
  c.bus_reset();
  const SetupPacket set_interface{request_type(false, RequestKind::kStandard, Recipient::kInterface),
                                  request::kSetInterface, alternate, kRomDfuInterface, 0};
  return c.control(standard_out(request::kSetAddress, 7), {}, {}).ok() &&
         c.control(standard_out(request::kSetConfiguration, 1), {}, {}).ok() && c.control(set_interface, {}, {}).ok();
}

// An IN control transfer: the data stage (resized to what came), or a
// failure in `result`.
inline Bytes control_in(host::FakeController& c, const SetupPacket& s, host::ControlResult* result = nullptr) {
  Bytes in(s.length);
  const host::ControlResult r = c.control(s, {}, in);
  in.resize(r.in_bytes);
  if (result != nullptr) *result = r;
  return in;
}

// The ASCII text of string descriptor `index` (UTF-16LE on the wire).
inline std::string read_string(host::FakeController& c, std::uint8_t index) {
  const Bytes d = control_in(c, get_descriptor(descriptor::kString, index, 255, kLangIdEnglishUs));
  std::string text;
  for (std::size_t i = 2; i + 1 < d.size() && i < d[0]; i += 2) text.push_back(static_cast<char>(d[i]));
  return text;
}

class SimDfuTransport final : public tools::usb::DfuTransport {
 public:
  explicit SimDfuTransport(Stm32RomBootloader& sim) : sim_(sim) {}

  void control_out(std::uint8_t request, std::uint16_t value, std::span<const std::uint8_t> data) override {
    const SetupPacket s = dfu_request(false, request, value, static_cast<std::uint16_t>(data.size()));
    check(s, transfer(s, data, {}));
  }
  std::size_t control_in(std::uint8_t request, std::uint16_t value, std::span<std::uint8_t> buffer) override {
    const SetupPacket s = dfu_request(true, request, value, static_cast<std::uint16_t>(buffer.size()));
    const host::ControlResult r = transfer(s, {}, buffer);
    check(s, r);
    return r.in_bytes;
  }
  std::size_t requests() const { return requests_; }

 private:
  host::ControlResult transfer(const SetupPacket& s, std::span<const std::uint8_t> out, std::span<std::uint8_t> in) {
    if (!sim_.attached()) {
      throw tools::usb::UsbTransferError(tools::usb::UsbTransferError::Kind::kGone,
                                         "request " + std::to_string(s.request) + ": no such device (it left the bus)");
    }
    ++requests_;
    const host::ControlResult r = sim_.controller().control(s, out, in);
    sim_.service();  // the device's main loop runs between transfers
    return r;
  }
  static void check(const SetupPacket& s, const host::ControlResult& r) {
    using tools::usb::UsbTransferError;
    if (r.stalled())
      throw UsbTransferError(UsbTransferError::Kind::kStall, "request " + std::to_string(s.request) + " stalled");
    if (!r.ok())
      throw UsbTransferError(UsbTransferError::Kind::kTimeout, "request " + std::to_string(s.request) + " NAKed");
  }

  Stm32RomBootloader& sim_;
  std::size_t requests_ = 0;
};

// The injected sleep: counts milliseconds, never waits.
struct FakeSleep {
  std::uint64_t total_ms = 0;
  std::size_t calls = 0;
  tools::usb::DfuClient::Sleep function() {
    return [this](std::uint32_t ms) {
      total_ms += ms;
      ++calls;
    };
  }
};

}  // namespace hadynet::usb::host_testing

#endif  // HADYNET_TEST_DFUSE_SIM_SIM_HOST_H_
