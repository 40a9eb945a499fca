// The whole device end of the link as pure code: received bytes in, bytes to
// transmit out. A LinkDispatcher and one LinkPort on it (link_port.h: the
// COBS StreamDecoder with its hard size limit, replies COBS-encoded and
// delimited); further ports may share the dispatcher. A board's transport calls
// receive() for every byte from its UART and sends what it returns. All
// buffers are members, sized at compile time (about 1.5 KiB, plus the
// autonomous loop's state, ~0.5 KiB for the hand's model).
#ifndef HADYNET_FIRMWARE_LINK_DEVICE_LINK_H_
#define HADYNET_FIRMWARE_LINK_DEVICE_LINK_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_contract.h"
#include "firmware/link/dispatcher.h"
#include "firmware/link/link_port.h"
#include "firmware/link/stream_decoder.h"

namespace hadynet::link {

template <firmware::GeneratedModel M>
class DeviceLink {
 public:
  explicit DeviceLink(firmware::HadynetRuntime<M>& runtime) noexcept : dispatcher_(runtime), port_(dispatcher_) {}

  DeviceLink(const DeviceLink&) = delete;
  DeviceLink& operator=(const DeviceLink&) = delete;

  // Feeds one received byte. Returns the wire bytes of the reply to send
  // (COBS + 0x00), or an empty span; valid until the next call. At most one
  // reply per received frame (and one per oversize frame).
  std::span<const std::uint8_t> receive(std::uint8_t byte) noexcept { return port_.receive(byte); }

  // The dispatcher, for a second byte stream on the same device state
  // (LinkPort, e.g. USB CDC-ACM beside the UART).
  LinkDispatcher<M>& dispatcher() noexcept { return dispatcher_; }
  const LinkDispatcher<M>& dispatcher() const noexcept { return dispatcher_; }
  // The autonomous 5 Hz loop the link feeds (firmware/app/period_loop.h).
  app::PeriodLoop<M>& loop() noexcept { return dispatcher_.loop(); }
  const app::PeriodLoop<M>& loop() const noexcept { return dispatcher_.loop(); }
  const StreamDecoder& decoder() const noexcept { return port_.decoder(); }

 private:
  LinkDispatcher<M> dispatcher_;  // before port_: the port refers to it
  LinkPort<M> port_;
};

}  // namespace hadynet::link

#endif  // HADYNET_FIRMWARE_LINK_DEVICE_LINK_H_
