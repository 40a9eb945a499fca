#include "test/usb_host/usbdevfs_node.h"

#include <linux/usbdevice_fs.h>
#include <sys/ioctl.h>  // _IOW and friends used by the USBDEVFS_* numbers
#include <umockdev.h>

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>

#include "test/usb_host/cdc_tty_bridge.h"

namespace hadynet::usb::host_testing {
namespace {

// Kernel speed code for USBDEVFS_GET_SPEED (enum usb_device_speed).
constexpr int kUsbSpeedFull = 2;

// Reads the unsigned int (or __u32) an ioctl argument points to.
bool read_uint_arg(UMockdevIoctlData* arg, unsigned& value) {
  UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(unsigned), nullptr);
  if (d == nullptr) return false;
  std::memcpy(&value, d->data, sizeof value);
  g_object_unref(d);
  return true;
}

}  // namespace

UsbdevfsNode::UsbdevfsNode(std::shared_ptr<EmulatedDevice> device, EnumeratedDevice enumerated)
    : device_(std::move(device)),
      engine_(*device_),
      enumerated_(std::move(enumerated)),
      configuration_(enumerated_.configuration.size() > 5 ? enumerated_.configuration[5] : 0) {}

UsbdevfsNode::~UsbdevfsNode() {
  for (auto* q : {&pending_, &completed_}) {
    for (Urb& u : *q) release(u);
  }
}

void UsbdevfsNode::set_bridge(std::unique_ptr<CdcTtyBridge> bridge) { bridge_ = std::move(bridge); }

void UsbdevfsNode::release(Urb& u) {
  if (u.buffer != nullptr) g_object_unref(u.buffer);
  if (u.data != nullptr) g_object_unref(u.data);
  if (u.client != nullptr) g_object_unref(u.client);
  u = Urb{};
}

UsbNodeStats UsbdevfsNode::stats() const {
  UsbNodeStats s = stats_;
  s.naks = engine_.naks();
  return s;
}

bool UsbdevfsNode::has_pending(EndpointAddress ep) const {
  for (const Urb& u : pending_) {
    if (u.t.ep == ep) return true;
  }
  return false;
}

void UsbdevfsNode::finish_all_pending(int status) {
  for (Urb& u : pending_) {
    u.t.stage = Transfer::Stage::kFinished;
    u.t.status = status;
    completed_.push_back(u);
  }
  pending_.clear();
}

void UsbdevfsNode::leave() {
  if (left_) return;
  left_ = true;
  finish_all_pending(-ENODEV);
  if (bridge_) bridge_->hang_up();
}

bool UsbdevfsNode::pump() {
  if (left_) return false;
  device_->service();
  if (!device_->attached()) {
    leave();
    return false;
  }
  if (bridge_ && configuration_ != 0) bridge_->pump(engine_);
  std::uint32_t blocked = 0;  // bit per endpoint index (number + 16 for IN)
  for (auto it = pending_.begin(); it != pending_.end();) {
    const std::uint32_t bit = 1u << ((it->t.ep & 0x0F) + (is_in(it->t.ep) ? 16 : 0));
    if ((blocked & bit) != 0 || !engine_.advance(it->t)) {
      blocked |= bit;
      ++it;
      continue;
    }
    completed_.push_back(*it);
    it = pending_.erase(it);
  }
  if (!device_->attached()) {  // left during a transfer (e.g. DFU_DETACH's status stage): it completed first
    leave();
    return false;
  }
  return true;
}

int UsbdevfsNode::submit_urb(UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
  Urb u;
  u.data = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_urb), nullptr);
  if (u.data == nullptr) return -EFAULT;
  const auto* v = reinterpret_cast<const usbdevfs_urb*>(u.data->data);
  const auto length = static_cast<std::size_t>(v->buffer_length < 0 ? 0 : v->buffer_length);
  if (length > 0) {
    u.buffer = umockdev_ioctl_data_resolve(u.data, offsetof(usbdevfs_urb, buffer), length, nullptr);
    if (u.buffer == nullptr) {
      release(u);
      return -EFAULT;
    }
  }
  u.t.type = v->type;
  u.t.ep = v->endpoint;
  u.t.flags = v->flags;
  u.t.bytes = std::span<std::uint8_t>(u.buffer != nullptr ? u.buffer->data : nullptr, length);
  u.t.stage = Transfer::Stage::kSetup;
  // The kernel's checks (proc_do_submiturb), as far as they matter here.
  host::FakeController& c = device_->controller();
  int error = 0;
  switch (u.t.type) {
    case USBDEVFS_URB_TYPE_CONTROL:
      if ((u.t.ep & 0x7F) != 0 || length < kSetupPacketSize || le16(u.t.bytes.data() + 6) > length - kSetupPacketSize) {
        error = -EINVAL;
      }
      break;
    case USBDEVFS_URB_TYPE_BULK:
    case USBDEVFS_URB_TYPE_INTERRUPT:
      if (endpoint_number(u.t.ep) == 0 || !c.endpoint_open(u.t.ep)) {
        error = -ENOENT;
      } else if (u.t.type == USBDEVFS_URB_TYPE_INTERRUPT && c.endpoint_type(u.t.ep) != EndpointType::kInterrupt) {
        error = -EINVAL;
      }
      break;
    default:  // isochronous: the devices have none
      error = -EINVAL;
  }
  if (error != 0) {
    release(u);
    return error;
  }
  u.client = UMOCKDEV_IOCTL_CLIENT(g_object_ref(client));
  ++stats_.urbs_submitted;
  if (engine_.arm(u.t)) {
    completed_.push_back(u);
    return 0;
  }
  pending_.push_back(u);
  pump();
  return 0;
}

int UsbdevfsNode::reap_urb(UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
  pump();
  for (auto it = completed_.begin(); it != completed_.end(); ++it) {
    if (it->client != client) continue;
    Urb u = *it;
    completed_.erase(it);
    auto* v = reinterpret_cast<usbdevfs_urb*>(u.data->data);
    v->status = u.t.status;
    v->actual_length = static_cast<int>(u.t.done);
    UMockdevIoctlData* ptr = umockdev_ioctl_data_resolve(arg, 0, sizeof(void*), nullptr);
    if (ptr == nullptr) {
      release(u);
      return -EFAULT;
    }
    umockdev_ioctl_data_set_ptr(ptr, 0, u.data);  // the client gets its own URB's address back
    g_object_unref(ptr);
    ++stats_.urbs_reaped;
    release(u);  // the reply holds its own references until it is written
    return 0;
  }
  return left_ ? -ENODEV : -EAGAIN;
}

int UsbdevfsNode::discard_urb(UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
  gulong address = 0;
  std::memcpy(&address, arg->data, sizeof address);  // the argument is the URB's address itself
  for (auto it = pending_.begin(); it != pending_.end(); ++it) {
    if (it->client != client || it->data->client_addr != address) continue;
    it->t.status = -ENOENT;
    it->t.stage = Transfer::Stage::kFinished;
    completed_.push_back(*it);
    pending_.erase(it);
    ++stats_.urbs_discarded;
    return 0;
  }
  return -EINVAL;  // unknown, or already finished (then it is reaped normally)
}

// Bus reset + SET_ADDRESS + SET_CONFIGURATION(current), as USBDEVFS_RESET does.
int UsbdevfsNode::reenumerate() {
  finish_all_pending(-ENODEV);
  device_->controller().bus_reset();
  const std::uint8_t std_out = request_type(false, RequestKind::kStandard, Recipient::kDevice);
  if (const int r = engine_.sync_control(std_out, request::kSetAddress, enumerated_.devnum, 0); r != 0) return r;
  if (configuration_ == 0) return 0;
  return engine_.sync_control(std_out, request::kSetConfiguration, static_cast<std::uint16_t>(configuration_), 0);
}

void UsbdevfsNode::write_configuration_attribute() const {
  if (configuration_attribute_.empty()) return;
  if (FILE* f = std::fopen(configuration_attribute_.c_str(), "w")) {
    std::fprintf(f, "%u\n", configuration_);
    std::fclose(f);
  }
}

void UsbdevfsNode::client_vanished(UMockdevIoctlClient* client) {
  for (auto* q : {&pending_, &completed_}) {
    for (auto it = q->begin(); it != q->end();) {
      if (it->client != client) {
        ++it;
        continue;
      }
      release(*it);
      it = q->erase(it);
    }
  }
}

int UsbdevfsNode::handle(UMockdevIoctlClient* client) {
  const unsigned long request = umockdev_ioctl_client_get_request(client);
  UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
  const std::uint8_t std_out_device = request_type(false, RequestKind::kStandard, Recipient::kDevice);
  ++stats_.ioctls;
  if (left_ && request != USBDEVFS_REAPURB && request != USBDEVFS_REAPURBNDELAY && request != USBDEVFS_DISCARDURB) {
    return -ENODEV;
  }
  switch (request) {
    case USBDEVFS_GET_CAPABILITIES: {
      UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(std::uint32_t), nullptr);
      if (d == nullptr) return -EFAULT;
      const std::uint32_t caps = USBDEVFS_CAP_ZERO_PACKET | USBDEVFS_CAP_BULK_CONTINUATION |
                                 USBDEVFS_CAP_NO_PACKET_SIZE_LIM | USBDEVFS_CAP_REAP_AFTER_DISCONNECT;
      std::memcpy(d->data, &caps, sizeof caps);
      g_object_unref(d);
      return 0;
    }
    case USBDEVFS_GET_SPEED:
      return kUsbSpeedFull;
    case USBDEVFS_SUBMITURB:
      return submit_urb(client, arg);
    case USBDEVFS_REAPURB:  // would block in the kernel; libusb only uses NDELAY
    case USBDEVFS_REAPURBNDELAY:
      return reap_urb(client, arg);
    case USBDEVFS_DISCARDURB:
      return discard_urb(client, arg);
    case USBDEVFS_CLAIMINTERFACE:
    case USBDEVFS_RELEASEINTERFACE: {
      unsigned interface = 0;
      if (!read_uint_arg(arg, interface)) return -EFAULT;
      const unsigned interfaces = enumerated_.configuration.size() > 4 ? enumerated_.configuration[4] : 0;
      return configuration_ != 0 && interface < interfaces ? 0 : -EINVAL;
    }
    case USBDEVFS_SETINTERFACE: {
      UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_setinterface), nullptr);
      if (d == nullptr) return -EFAULT;
      usbdevfs_setinterface si{};
      std::memcpy(&si, d->data, sizeof si);
      g_object_unref(d);
      if (!enumerated_.has_alternate(si.interface, si.altsetting)) return -EINVAL;  // the kernel checks its copy
      return engine_.sync_control(request_type(false, RequestKind::kStandard, Recipient::kInterface),
                                  request::kSetInterface, static_cast<std::uint16_t>(si.altsetting),
                                  static_cast<std::uint16_t>(si.interface));
    }
    case USBDEVFS_SETCONFIGURATION: {
      unsigned value = 0;
      if (!read_uint_arg(arg, value)) return -EFAULT;
      const unsigned configuration = static_cast<int>(value) < 0 ? 0 : value;  // -1: unconfigure
      const int r =
          engine_.sync_control(std_out_device, request::kSetConfiguration, static_cast<std::uint16_t>(configuration), 0);
      if (r == 0) {
        configuration_ = configuration;
        write_configuration_attribute();
      }
      return r;
    }
    case USBDEVFS_CLEAR_HALT: {
      unsigned ep = 0;
      if (!read_uint_arg(arg, ep)) return -EFAULT;
      return engine_.sync_control(request_type(false, RequestKind::kStandard, Recipient::kEndpoint),
                                  request::kClearFeature, kFeatureEndpointHalt, static_cast<std::uint16_t>(ep));
    }
    case USBDEVFS_RESETEP:  // host-side toggle only
      return 0;
    case USBDEVFS_RESET:
      return reenumerate();
    case USBDEVFS_GETDRIVER:
      return -ENODATA;  // no kernel driver bound to any interface
    case USBDEVFS_IOCTL:
    case USBDEVFS_DISCONNECT_CLAIM:
      return 0;  // detach/attach kernel drivers: there are none
    default:
      ++stats_.unknown_ioctls;
      stats_.last_unknown_ioctl = request;
      return -ENOTTY;
  }
}

}  // namespace hadynet::usb::host_testing
