// CDC-ACM (USB CDC 1.2, PSTN 1.2 ACM model) carrying a byte stream: bulk OUT
// bytes go, one by one, into the same receive path as the UART
// (`E::receive(byte)`, e.g. app::UartEndpoint or link::DeviceLink); the bytes
// it returns go out on bulk IN. So the link protocol runs over /dev/ttyACM*
// unchanged.
//
// Flow control without loss: received bytes are fed to the endpoint in
// service() (main loop, not in an event) only while the transmit ring has
// room for the largest reply (kMaxReply bytes); the OUT endpoint is re-armed
// only when the whole packet was consumed, so the host is NAKed meanwhile.
// A bulk IN packet of 64 bytes that empties the ring is followed by a
// zero-length packet (hosts' read URBs end on a short packet).
//
// Line coding, control line state and breaks are recorded and reported; they
// change nothing (the link has no baud rate). The notification endpoint is
// declared (hosts' ACM drivers require it) and never sends.
#ifndef HADYNET_FIRMWARE_USB_CDC_ACM_H_
#define HADYNET_FIRMWARE_USB_CDC_ACM_H_

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/usb/device_controller.h"
#include "firmware/usb/usb_function.h"
#include "firmware/usb/usb_spec.h"

namespace hadynet::usb {

// Anything that takes received bytes and answers with bytes to send, valid
// until the next call (the UART's link hook).
template <class E>
concept ByteEndpoint = requires(E& e, std::uint8_t b) {
  { e.receive(b) } -> std::convertible_to<std::span<const std::uint8_t>>;
};

namespace cdc {
inline constexpr std::uint8_t kClassComm = 0x02;     // Communications Device Class
inline constexpr std::uint8_t kSubclassAcm = 0x02;   // Abstract Control Model
inline constexpr std::uint8_t kProtocolNone = 0x00;  // no AT commands
inline constexpr std::uint8_t kClassData = 0x0A;
inline constexpr std::uint8_t kSetLineCoding = 0x20;
inline constexpr std::uint8_t kGetLineCoding = 0x21;
inline constexpr std::uint8_t kSetControlLineState = 0x22;
inline constexpr std::uint8_t kSendBreak = 0x23;
inline constexpr std::size_t kLineCodingSize = 7;
inline constexpr std::uint16_t kNotifyMaxPacket = 16;  // SERIAL_STATE (10 bytes) fits one packet
inline constexpr std::uint16_t kDataMaxPacket = 64;
}  // namespace cdc

struct LineCoding {
  std::uint32_t baud = 115200;  // dwDTERate, bits/s
  std::uint8_t stop_bits = 0;   // bCharFormat: 0 = 1, 1 = 1.5, 2 = 2
  std::uint8_t parity = 0;      // bParityType: 0 none, 1 odd, 2 even, 3 mark, 4 space
  std::uint8_t data_bits = 8;   // bDataBits: 5, 6, 7, 8 or 16
};

struct CdcAcmLayout {
  std::uint8_t comm_interface = 0;  // the data interface is comm_interface + 1
  EndpointAddress notify_in = 0x81;
  EndpointAddress data_out = 0x02;
  EndpointAddress data_in = 0x82;
};

template <ByteEndpoint E, std::size_t kMaxReply>
class CdcAcm final : public UsbFunction {
 public:
  // Two worst-case replies: one being sent, one being produced.
  static constexpr std::size_t kTxCapacity = 2 * kMaxReply;

  CdcAcm(E& endpoint, const CdcAcmLayout& layout) noexcept : endpoint_(endpoint), layout_(layout) {}

  bool owns_interface(std::uint8_t interface) const noexcept override {
    return interface == layout_.comm_interface || interface == layout_.comm_interface + 1;
  }
  bool owns_endpoint(EndpointAddress ep) const noexcept override {
    return ep == layout_.notify_in || ep == layout_.data_out || ep == layout_.data_in;
  }

  ControlReply control_setup(const SetupPacket& s, std::span<std::uint8_t> buffer) noexcept override {
    if (s.recipient() != Recipient::kInterface || s.index != layout_.comm_interface) return ControlReply::stall();
    switch (s.request) {
      case cdc::kSetLineCoding:
        if (s.is_in() || s.value != 0 || s.length != cdc::kLineCodingSize) break;
        return ControlReply::data_out();
      case cdc::kGetLineCoding:
        if (!s.is_in() || s.value != 0 || s.length != cdc::kLineCodingSize) break;
        put_le32(buffer.data(), line_coding_.baud);
        buffer[4] = line_coding_.stop_bits;
        buffer[5] = line_coding_.parity;
        buffer[6] = line_coding_.data_bits;
        return ControlReply::data_in(cdc::kLineCodingSize);
      case cdc::kSetControlLineState:
        if (s.is_in() || s.length != 0 || s.value > 3) break;
        dtr_ = (s.value & 1) != 0;
        rts_ = (s.value & 2) != 0;
        return ControlReply::ack();
      case cdc::kSendBreak:
        if (s.is_in() || s.length != 0) break;
        break_ms_ = s.value;  // 0xFFFF: until SEND_BREAK(0)
        ++breaks_;
        return ControlReply::ack();
      default:
        break;
    }
    return ControlReply::stall();
  }

  bool control_out(const SetupPacket& s, std::span<const std::uint8_t> data) noexcept override {
    if (s.request != cdc::kSetLineCoding || data.size() != cdc::kLineCodingSize) return false;
    LineCoding c;
    c.baud = get_le32(data.data());
    c.stop_bits = data[4];
    c.parity = data[5];
    c.data_bits = data[6];
    const bool bits_ok = (c.data_bits >= 5 && c.data_bits <= 8) || c.data_bits == 16;
    if (c.baud == 0 || c.stop_bits > 2 || c.parity > 4 || !bits_ok) return false;
    line_coding_ = c;
    return true;
  }

  bool configure(DeviceController& controller) noexcept override {
    controller_ = &controller;
    reset_transfers();
    if (!controller.open_endpoint({layout_.notify_in, EndpointType::kInterrupt, cdc::kNotifyMaxPacket}) ||
        !controller.open_endpoint({layout_.data_out, EndpointType::kBulk, cdc::kDataMaxPacket}) ||
        !controller.open_endpoint({layout_.data_in, EndpointType::kBulk, cdc::kDataMaxPacket})) {
      controller_ = nullptr;
      return false;
    }
    arm_out();
    return true;
  }

  void deconfigure() noexcept override {
    controller_ = nullptr;
    reset_transfers();
  }

  void transfer_complete(EndpointAddress ep, std::size_t bytes) noexcept override {
    if (ep == layout_.data_out && out_armed_) {
      out_armed_ = false;
      rx_size_ = bytes < cdc::kDataMaxPacket ? bytes : cdc::kDataMaxPacket;
      rx_pos_ = 0;
    } else if (ep == layout_.data_in && in_busy_) {
      in_busy_ = false;
      tx_pop(in_flight_);
      const bool zlp = in_flight_ == cdc::kDataMaxPacket && tx_size_ == 0;
      in_flight_ = 0;
      if (zlp) {
        start_in(0);
      } else {
        start_tx();
      }
    }
  }

  void halt_changed(EndpointAddress ep, bool halted) noexcept override {
    if (ep == layout_.data_out) {
      out_armed_ = false;
      out_halted_ = halted;
      if (!halted && rx_pos_ == rx_size_) arm_out();
    } else if (ep == layout_.data_in) {
      if (in_busy_) tx_pop(in_flight_);  // the packet is lost with the transfer
      in_busy_ = false;
      in_flight_ = 0;
      in_halted_ = halted;
      if (!halted) start_tx();
    }
  }

  // Feeds received bytes to the endpoint while the ring has room for a
  // whole reply; re-arms OUT when the packet is consumed; starts IN.
  void service() noexcept override {
    if (controller_ == nullptr) return;
    while (rx_pos_ < rx_size_ && kTxCapacity - tx_size_ >= kMaxReply) {
      const std::span<const std::uint8_t> reply = endpoint_.receive(rx_[rx_pos_++]);
      tx_push(reply);
    }
    if (rx_pos_ == rx_size_ && !out_armed_ && !out_halted_) arm_out();
    start_tx();
  }

  const LineCoding& line_coding() const noexcept { return line_coding_; }
  bool dtr() const noexcept { return dtr_; }
  bool rts() const noexcept { return rts_; }
  std::uint16_t break_ms() const noexcept { return break_ms_; }
  std::uint32_t breaks() const noexcept { return breaks_; }
  std::size_t tx_pending() const noexcept { return tx_size_; }
  std::size_t rx_pending() const noexcept { return rx_size_ - rx_pos_; }
  std::size_t dropped_reply_bytes() const noexcept { return dropped_; }

 private:
  void reset_transfers() noexcept {
    rx_size_ = rx_pos_ = 0;
    tx_head_ = tx_size_ = 0;
    in_flight_ = 0;
    in_busy_ = out_armed_ = false;
    in_halted_ = out_halted_ = false;
  }

  void arm_out() noexcept {
    if (controller_ == nullptr || out_armed_) return;
    rx_size_ = rx_pos_ = 0;
    out_armed_ = controller_->start_transfer(layout_.data_out, std::span<std::uint8_t>(rx_));
  }

  void start_tx() noexcept {
    if (controller_ == nullptr || in_busy_ || in_halted_ || tx_size_ == 0) return;
    const std::size_t n = tx_size_ < cdc::kDataMaxPacket ? tx_size_ : cdc::kDataMaxPacket;
    for (std::size_t i = 0; i < n; ++i) packet_[i] = tx_[(tx_head_ + i) % kTxCapacity];
    start_in(n);
  }

  void start_in(std::size_t n) noexcept {
    in_busy_ = controller_->start_transfer(layout_.data_in, std::span<std::uint8_t>(packet_, n));
    in_flight_ = in_busy_ ? n : 0;
  }

  void tx_push(std::span<const std::uint8_t> bytes) noexcept {
    for (const std::uint8_t b : bytes) {
      if (tx_size_ == kTxCapacity) {  // cannot happen with a correct kMaxReply
        ++dropped_;
        continue;
      }
      tx_[(tx_head_ + tx_size_) % kTxCapacity] = b;
      ++tx_size_;
    }
  }

  void tx_pop(std::size_t n) noexcept {
    if (n > tx_size_) n = tx_size_;
    tx_head_ = (tx_head_ + n) % kTxCapacity;
    tx_size_ -= n;
  }

  E& endpoint_;
  CdcAcmLayout layout_;
  DeviceController* controller_ = nullptr;  // set while configured
  LineCoding line_coding_{};
  bool dtr_ = false;
  bool rts_ = false;
  std::uint16_t break_ms_ = 0;
  std::uint32_t breaks_ = 0;

  std::uint8_t rx_[cdc::kDataMaxPacket] = {};
  std::size_t rx_size_ = 0;  // bytes of the last OUT packet
  std::size_t rx_pos_ = 0;   // of those, fed to the endpoint
  bool out_armed_ = false;
  bool out_halted_ = false;

  std::uint8_t tx_[kTxCapacity] = {};
  std::size_t tx_head_ = 0;
  std::size_t tx_size_ = 0;
  std::uint8_t packet_[cdc::kDataMaxPacket] = {};
  std::size_t in_flight_ = 0;
  bool in_busy_ = false;
  bool in_halted_ = false;
  std::size_t dropped_ = 0;
};

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_CDC_ACM_H_
