#include "firmware/usb/usb_device.h"

namespace hadynet::usb {

namespace {

constexpr std::size_t min_size(std::size_t a, std::size_t b) noexcept { return a < b ? a : b; }

bool is_halt_request(const SetupPacket& s) noexcept {
  return !s.is_in() && s.length == 0 && s.value == kFeatureEndpointHalt;
}

}  // namespace

void UsbDevice::start() noexcept {
  controller_.init(*this);
  controller_.set_connected(true);
}

void UsbDevice::handle(const ControllerEvent& event) noexcept {
  switch (event.type) {
    case ControllerEvent::Type::kBusReset:
      bus_reset();
      break;
    case ControllerEvent::Type::kSetup:
      setup(parse_setup(event.setup));
      break;
    case ControllerEvent::Type::kTransferComplete:
      if (endpoint_number(event.endpoint) == 0) {
        if (is_in(event.endpoint)) {
          ep0_in_complete(event.bytes);
        } else {
          ep0_out_complete(event.bytes);
        }
      } else if (state_ == DeviceState::kConfigured) {
        if (UsbFunction* f = function_for_endpoint(event.endpoint)) f->transfer_complete(event.endpoint, event.bytes);
      }
      break;
    case ControllerEvent::Type::kSuspend:
      suspended_ = true;
      break;
    case ControllerEvent::Type::kResume:
      suspended_ = false;
      break;
  }
}

void UsbDevice::service() noexcept {
  for (UsbFunction* f : functions_) f->service();
}

bool UsbDevice::endpoint_halted(EndpointAddress ep) const noexcept {
  const std::size_t i = halt_index(ep);
  return i < sizeof(halted_) && halted_[i];
}

std::size_t UsbDevice::halt_index(EndpointAddress ep) noexcept {
  return static_cast<std::size_t>(endpoint_number(ep)) * 2 + (is_in(ep) ? 1 : 0);
}

void UsbDevice::bus_reset() noexcept {
  // The controller has dropped every transfer and closed endpoints 1..3.
  if (state_ == DeviceState::kConfigured) deconfigure();
  state_ = DeviceState::kDefault;
  address_ = 0;
  address_pending_ = false;
  suspended_ = false;
  stage_ = ControlStage::kIdle;
  owner_ = nullptr;
  for (bool& h : halted_) h = false;
}

// ---- EP0 state machine ------------------------------------------------------

void UsbDevice::setup(const SetupPacket& s) noexcept {
  // A SETUP ends whatever control transfer was in progress (the controller
  // cancelled its EP0 transfers and cleared the stall).
  setup_ = s;
  owner_ = nullptr;
  data_size_ = 0;
  data_done_ = 0;
  last_packet_ = 0;
  address_pending_ = false;
  stage_ = ControlStage::kIdle;

  ControlReply reply = ControlReply::stall();
  if (s.kind() == RequestKind::kStandard) {
    switch (s.recipient()) {
      case Recipient::kDevice:
        reply = standard_device(s);
        break;
      case Recipient::kInterface:
        reply = standard_interface(s);
        break;
      case Recipient::kEndpoint:
        reply = standard_endpoint(s);
        break;
      default:
        break;
    }
  } else if (s.kind() == RequestKind::kClass && state_ == DeviceState::kConfigured) {
    UsbFunction* f = nullptr;
    if (s.recipient() == Recipient::kInterface && (s.index >> 8) == 0) {
      f = function_for_interface(s.index_low());
    } else if (s.recipient() == Recipient::kEndpoint && (s.index >> 8) == 0 && endpoint_number(s.index_low()) != 0) {
      f = function_for_endpoint(s.index_low());
    }
    if (f != nullptr) {
      owner_ = f;
      reply = f->control_setup(s, buffer_);
    }
  }
  accept(reply);
}

void UsbDevice::accept(const ControlReply& reply) noexcept {
  switch (reply.kind) {
    case ControlReply::Kind::kStall:
      stall();
      return;
    case ControlReply::Kind::kAck:
      if (setup_.length != 0) {
        stall();  // a request with a data stage needs one
        return;
      }
      start_status_in();
      return;
    case ControlReply::Kind::kDataIn:
      if (!setup_.is_in()) {
        stall();
        return;
      }
      if (setup_.length == 0) {  // no data stage: only the status
        start_status_in();
        return;
      }
      data_size_ = min_size(min_size(reply.size, setup_.length), kControlBufferSize);
      stage_ = ControlStage::kDataIn;
      send_in_packet();
      return;
    case ControlReply::Kind::kDataOut:
      if (setup_.is_in() || setup_.length == 0 || setup_.length > kControlBufferSize) {
        stall();
        return;
      }
      stage_ = ControlStage::kDataOut;
      arm_data_out();
      return;
  }
}

void UsbDevice::stall() noexcept {
  controller_.stall_control();
  stage_ = ControlStage::kStalled;
  owner_ = nullptr;
  address_pending_ = false;
}

void UsbDevice::send_in_packet() noexcept {
  last_packet_ = min_size(kEp0MaxPacket, data_size_ - data_done_);
  if (!controller_.start_transfer(in_endpoint(0), std::span<std::uint8_t>(buffer_ + data_done_, last_packet_))) {
    stall();
  }
}

void UsbDevice::arm_data_out() noexcept {
  last_packet_ = min_size(kEp0MaxPacket, static_cast<std::size_t>(setup_.length) - data_done_);
  if (!controller_.start_transfer(out_endpoint(0), std::span<std::uint8_t>(buffer_ + data_done_, last_packet_))) {
    stall();
  }
}

void UsbDevice::start_status_in() noexcept {
  stage_ = ControlStage::kStatusIn;
  if (!controller_.start_transfer(in_endpoint(0), std::span<std::uint8_t>())) stall();
}

void UsbDevice::start_status_out() noexcept {
  stage_ = ControlStage::kStatusOut;
  if (!controller_.start_transfer(out_endpoint(0), std::span<std::uint8_t>(status_buffer_))) stall();
}

void UsbDevice::ep0_in_complete(std::size_t bytes) noexcept {
  (void)bytes;  // our own packet size is authoritative
  if (stage_ == ControlStage::kDataIn) {
    data_done_ += last_packet_;
    if (data_done_ < data_size_) {
      send_in_packet();
    } else if (last_packet_ == kEp0MaxPacket && data_size_ < setup_.length) {
      // The reply ended on a full packet but is shorter than wLength: a
      // zero-length packet tells the host it is complete.
      send_in_packet();  // data_done_ == data_size_: 0 bytes
    } else {
      start_status_out();
    }
  } else if (stage_ == ControlStage::kStatusIn) {
    status_complete();
  }
}

void UsbDevice::ep0_out_complete(std::size_t bytes) noexcept {
  if (stage_ == ControlStage::kDataOut) {
    const std::size_t got = min_size(bytes, last_packet_);
    data_done_ += got;
    if (got < last_packet_ || data_done_ >= setup_.length) {
      const bool ok = owner_ != nullptr &&
                      owner_->control_out(setup_, std::span<const std::uint8_t>(buffer_, data_done_));
      if (ok) {
        start_status_in();
      } else {
        stall();
      }
    } else {
      arm_data_out();
    }
  } else if (stage_ == ControlStage::kStatusOut) {
    stage_ = ControlStage::kIdle;
    if (owner_ != nullptr) owner_->control_complete(setup_);
    owner_ = nullptr;
  }
}

void UsbDevice::status_complete() noexcept {
  stage_ = ControlStage::kIdle;
  if (address_pending_) {
    // SET_ADDRESS takes effect after its status stage (USB 2.0 §9.4.6).
    address_pending_ = false;
    address_ = pending_address_;
    state_ = address_ != 0 ? DeviceState::kAddressed : DeviceState::kDefault;
  }
  UsbFunction* owner = owner_;
  owner_ = nullptr;
  if (owner != nullptr) owner->control_complete(setup_);
}

// ---- standard requests --------------------------------------------------------

ControlReply UsbDevice::standard_device(const SetupPacket& s) noexcept {
  switch (s.request) {
    case request::kGetStatus:
      if (!s.is_in() || s.value != 0 || s.index != 0 || s.length != 2 || state_ == DeviceState::kDefault) break;
      buffer_[0] = self_powered_ ? 1 : 0;  // bit 1 (remote wakeup) never set: not supported
      buffer_[1] = 0;
      return ControlReply::data_in(2);
    case request::kSetAddress:
      if (s.is_in() || s.index != 0 || s.length != 0 || s.value > 127 || state_ == DeviceState::kConfigured) break;
      pending_address_ = static_cast<std::uint8_t>(s.value);
      controller_.set_address(pending_address_);  // before the status stage: the seam's contract
      address_pending_ = true;
      return ControlReply::ack();
    case request::kGetDescriptor:
      if (!s.is_in()) break;
      return get_descriptor(s);
    case request::kGetConfiguration:
      if (!s.is_in() || s.value != 0 || s.index != 0 || s.length != 1 || state_ == DeviceState::kDefault) break;
      buffer_[0] = configuration();
      return ControlReply::data_in(1);
    case request::kSetConfiguration:
      if (s.is_in() || s.index != 0 || s.length != 0 || state_ == DeviceState::kDefault) break;
      if (!set_configuration(s.value)) break;
      return ControlReply::ack();
    default:
      // CLEAR/SET_FEATURE: neither remote wakeup nor test mode (high speed)
      // is supported; SET_DESCRIPTOR is optional and refused.
      break;
  }
  return ControlReply::stall();
}

ControlReply UsbDevice::standard_interface(const SetupPacket& s) noexcept {
  if (state_ != DeviceState::kConfigured || (s.index >> 8) != 0) return ControlReply::stall();
  const std::uint8_t interface = s.index_low();
  UsbFunction* f = function_for_interface(interface);
  if (f == nullptr) return ControlReply::stall();
  switch (s.request) {
    case request::kGetStatus:
      if (!s.is_in() || s.value != 0 || s.length != 2) break;
      buffer_[0] = 0;
      buffer_[1] = 0;
      return ControlReply::data_in(2);
    case request::kGetInterface:
      if (!s.is_in() || s.value != 0 || s.length != 1) break;
      buffer_[0] = f->alternate(interface);
      return ControlReply::data_in(1);
    case request::kSetInterface:
      if (s.is_in() || s.length != 0 || s.value > 0xFF) break;
      if (!f->set_alternate(interface, static_cast<std::uint8_t>(s.value))) break;
      return ControlReply::ack();
    case request::kGetDescriptor:
      if (!s.is_in()) break;
      owner_ = f;
      return f->control_setup(s, buffer_);
    default:
      break;
  }
  return ControlReply::stall();
}

ControlReply UsbDevice::standard_endpoint(const SetupPacket& s) noexcept {
  const EndpointAddress ep = s.index_low();
  if ((s.index & 0xFF70) != 0 || !endpoint_exists(ep)) return ControlReply::stall();
  const bool ep0 = endpoint_number(ep) == 0;
  switch (s.request) {
    case request::kGetStatus:
      if (!s.is_in() || s.value != 0 || s.length != 2) break;
      buffer_[0] = ep0 ? 0 : (halted_[halt_index(ep)] ? 1 : 0);
      buffer_[1] = 0;
      return ControlReply::data_in(2);
    case request::kClearFeature:
      if (!is_halt_request(s)) break;
      if (!ep0) {
        // Also when not halted: the data toggle goes back to DATA0.
        halted_[halt_index(ep)] = false;
        controller_.set_endpoint_halt(ep, false);
        if (UsbFunction* f = function_for_endpoint(ep)) f->halt_changed(ep, false);
      }
      return ControlReply::ack();
    case request::kSetFeature:
      if (!is_halt_request(s) || ep0) break;
      halted_[halt_index(ep)] = true;
      controller_.set_endpoint_halt(ep, true);
      if (UsbFunction* f = function_for_endpoint(ep)) f->halt_changed(ep, true);
      return ControlReply::ack();
    default:
      break;
  }
  return ControlReply::stall();
}

ControlReply UsbDevice::get_descriptor(const SetupPacket& s) noexcept {
  std::span<const std::uint8_t> source;
  switch (s.value_high()) {
    case descriptor::kDevice:
      if (s.value_low() != 0 || s.index != 0) return ControlReply::stall();
      source = descriptors_.device;
      break;
    case descriptor::kConfiguration:
      if (s.value_low() != 0 || s.index != 0) return ControlReply::stall();
      source = descriptors_.configuration;
      break;
    case descriptor::kString: {
      const std::size_t n = string_descriptor(s.value_low());
      if (n == 0) return ControlReply::stall();
      return ControlReply::data_in(n);
    }
    default:
      // Device qualifier and other-speed configuration: a full-speed-only
      // device answers STALL (USB 2.0 §9.6.2). Anything else is unknown.
      return ControlReply::stall();
  }
  if (source.size() > kControlBufferSize) return ControlReply::stall();
  for (std::size_t i = 0; i < source.size(); ++i) buffer_[i] = source[i];
  return ControlReply::data_in(source.size());
}

std::size_t UsbDevice::string_descriptor(std::uint8_t index) noexcept {
  if (index == 0) {
    buffer_[0] = 4;
    buffer_[1] = descriptor::kString;
    put_le16(buffer_ + 2, kLangIdEnglishUs);
    return 4;
  }
  if (index >= descriptors_.strings.size() || descriptors_.strings[index] == nullptr) return 0;
  const char* text = descriptors_.strings[index];
  std::size_t n = 0;
  while (n < kMaxStringChars && text[n] != '\0') {
    buffer_[2 + 2 * n] = static_cast<std::uint8_t>(text[n] & 0x7F);  // ASCII -> UTF-16LE
    buffer_[3 + 2 * n] = 0;
    ++n;
  }
  buffer_[0] = static_cast<std::uint8_t>(2 + 2 * n);
  buffer_[1] = descriptor::kString;
  return 2 + 2 * n;
}

bool UsbDevice::set_configuration(std::uint16_t value) noexcept {
  if (value > 1) return false;
  if (state_ == DeviceState::kConfigured) deconfigure();
  state_ = DeviceState::kAddressed;
  if (value == 0) return true;
  for (UsbFunction* f : functions_) {
    if (!f->configure(controller_)) {
      for (UsbFunction* g : functions_) g->deconfigure();
      return false;
    }
  }
  state_ = DeviceState::kConfigured;
  return true;
}

void UsbDevice::deconfigure() noexcept {
  for (UsbFunction* f : functions_) f->deconfigure();
  // Close every endpoint the configuration declares.
  const std::span<const std::uint8_t> c = descriptors_.configuration;
  for (std::size_t i = 0; i + 1 < c.size() && c[i] >= 2; i += c[i]) {
    if (c[i + 1] == descriptor::kEndpoint && i + 2 < c.size()) controller_.close_endpoint(c[i + 2]);
  }
  for (bool& h : halted_) h = false;
  state_ = DeviceState::kAddressed;
}

bool UsbDevice::endpoint_exists(EndpointAddress ep) const noexcept {
  if (endpoint_number(ep) == 0) return true;
  if (state_ != DeviceState::kConfigured) return false;
  const std::span<const std::uint8_t> c = descriptors_.configuration;
  for (std::size_t i = 0; i + 1 < c.size() && c[i] >= 2; i += c[i]) {
    if (c[i + 1] == descriptor::kEndpoint && i + 2 < c.size() && c[i + 2] == ep) return true;
  }
  return false;
}

UsbFunction* UsbDevice::function_for_interface(std::uint8_t interface) const noexcept {
  for (UsbFunction* f : functions_) {
    if (f->owns_interface(interface)) return f;
  }
  return nullptr;
}

UsbFunction* UsbDevice::function_for_endpoint(EndpointAddress ep) const noexcept {
  for (UsbFunction* f : functions_) {
    if (f->owns_endpoint(ep)) return f;
  }
  return nullptr;
}

}  // namespace hadynet::usb
