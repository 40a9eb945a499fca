// ============================================================================
//  THE LINK HOOK: the one place where bytes received on the UART become the
//  bytes sent back.
//
//  firmware_main.cc feeds every received byte to UartEndpoint::receive() and
//  writes whatever it returns to the UART, unchanged. Nothing else in the
//  application reads or writes the UART. The endpoint is the link protocol's
//  device end (firmware/link/device_link.h, docs/protocol.md): COBS frames
//  with a hard size limit, CRC-32, sequence numbers, one reply per request,
//  an error reply (and no state change) for anything malformed.
// ============================================================================
#ifndef HADYNET_FIRMWARE_APP_UART_ENDPOINT_H_
#define HADYNET_FIRMWARE_APP_UART_ENDPOINT_H_

#include <cstdint>
#include <span>

#include "firmware/app/period_loop.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/link/device_link.h"

namespace hadynet::app {

template <firmware::GeneratedModel M>
class UartEndpoint {
 public:
  explicit UartEndpoint(firmware::HadynetRuntime<M>& runtime) noexcept : link_(runtime) {}

  // One received byte in; the bytes to send back (possibly none), valid
  // until the next call.
  std::span<const std::uint8_t> receive(std::uint8_t byte) noexcept { return link_.receive(byte); }

  // The autonomous 5 Hz loop the link feeds (muscle states, tare) and
  // reports (period records); firmware_main.cc runs its periods.
  PeriodLoop<M>& loop() noexcept { return link_.loop(); }

  // The device state behind the link, for a second byte stream on it (the
  // USB CDC-ACM port, firmware/app/usb_link.h).
  link::LinkDispatcher<M>& dispatcher() noexcept { return link_.dispatcher(); }

 private:
  link::DeviceLink<M> link_;
};

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_UART_ENDPOINT_H_
