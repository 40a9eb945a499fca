#include "test/dfuse_sim/large_control_bridge.h"

namespace hadynet::usb::host_testing {

void LargeControlBridge::init(ControllerEventHandler& handler) noexcept {
  stack_ = &handler;
  stage_ = Stage::kNone;
  controller_.init(*this);
}

bool LargeControlBridge::takes(const SetupPacket& s) const noexcept {
  return device_ != nullptr && device_->state() == DeviceState::kConfigured && s.kind() == RequestKind::kClass &&
         s.recipient() == Recipient::kInterface && s.index == interface_ && s.length > kControlBufferSize;
}

void LargeControlBridge::handle(const ControllerEvent& event) noexcept {
  switch (event.type) {
    case ControllerEvent::Type::kSetup: {
      const SetupPacket s = parse_setup(event.setup);
      stage_ = Stage::kNone;  // a SETUP ends any transfer, ours too
      if (takes(s)) {
        begin(s);
        return;
      }
      break;
    }
    case ControllerEvent::Type::kBusReset:
      stage_ = Stage::kNone;
      break;
    case ControllerEvent::Type::kTransferComplete:
      if (stage_ != Stage::kNone && endpoint_number(event.endpoint) == 0) {
        if (is_in(event.endpoint)) {
          in_complete();
        } else {
          out_complete(event.bytes);
        }
        return;
      }
      break;
    default:
      break;
  }
  if (stack_ != nullptr) stack_->handle(event);
}

void LargeControlBridge::fail() noexcept {
  stage_ = Stage::kNone;
  controller_.stall_control();
}

void LargeControlBridge::begin(const SetupPacket& s) noexcept {
  setup_ = s;
  done_ = 0;
  ++transfers_;
  if (s.length > kMaxDataStage) {
    fail();  // larger than any block the function serves
    return;
  }
  const ControlReply reply = function_.control_setup(s, std::span<std::uint8_t>(buffer_.data(), s.length));
  if (reply.kind == ControlReply::Kind::kDataIn && s.is_in()) {
    size_ = reply.size < s.length ? reply.size : s.length;
    stage_ = Stage::kDataIn;
    send_packet();
  } else if (reply.kind == ControlReply::Kind::kDataOut && !s.is_in()) {
    size_ = s.length;
    stage_ = Stage::kDataOut;
    arm_out();
  } else {
    fail();  // kStall, or an answer that does not fit the direction
  }
}

void LargeControlBridge::send_packet() noexcept {
  packet_ = size_ - done_ < kEp0MaxPacket ? size_ - done_ : kEp0MaxPacket;
  if (!controller_.start_transfer(in_endpoint(0), std::span<std::uint8_t>(buffer_.data() + done_, packet_))) fail();
}

void LargeControlBridge::arm_out() noexcept {
  packet_ = size_ - done_ < kEp0MaxPacket ? size_ - done_ : kEp0MaxPacket;
  if (!controller_.start_transfer(out_endpoint(0), std::span<std::uint8_t>(buffer_.data() + done_, packet_))) fail();
}

void LargeControlBridge::in_complete() noexcept {
  if (stage_ == Stage::kDataIn) {
    done_ += packet_;
    if (done_ < size_) {
      send_packet();
    } else if (packet_ == kEp0MaxPacket && size_ < setup_.length) {
      send_packet();  // a zero-length packet ends a reply shorter than wLength
    } else {
      stage_ = Stage::kStatusOut;
      if (!controller_.start_transfer(out_endpoint(0), std::span<std::uint8_t>(status_))) fail();
    }
  } else if (stage_ == Stage::kStatusIn) {
    stage_ = Stage::kNone;
    function_.control_complete(setup_);
  }
}

void LargeControlBridge::out_complete(std::size_t bytes) noexcept {
  if (stage_ == Stage::kDataOut) {
    const std::size_t got = bytes < packet_ ? bytes : packet_;
    done_ += got;
    if (got < packet_ || done_ >= size_) {
      if (!function_.control_out(setup_, std::span<const std::uint8_t>(buffer_.data(), done_))) {
        fail();
        return;
      }
      stage_ = Stage::kStatusIn;
      if (!controller_.start_transfer(in_endpoint(0), std::span<std::uint8_t>())) fail();
    } else {
      arm_out();
    }
  } else if (stage_ == Stage::kStatusOut) {
    stage_ = Stage::kNone;
    function_.control_complete(setup_);
  }
}

}  // namespace hadynet::usb::host_testing
