#include "test/usb_host/umockdev_usb_device.h"

#include <linux/usbdevice_fs.h>
#include <sys/ioctl.h>  // _IOW and friends used by the USBDEVFS_* numbers
#include <umockdev.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <deque>
#include <mutex>
#include <span>
#include <string>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/flash/simulated_nor_flash.h"
#include "firmware/flash/stm32f405_flash_layout.h"
#include "firmware/link/device_link.h"
#include "firmware/link/frame.h"
#include "firmware/usb/hadynet_usb_device.h"
#include "firmware/usb/host/fake_controller.h"

namespace hadynet::usb::host_testing {
namespace {

using host::FakeController;
using host::Handshake;
using Usb = HadynetUsbDevice<Q, link::DeviceLink<Q>, link::kMaxWireFrame>;

// DFU_DETACH has nowhere to go on the host: recorded, nothing else.
struct CountingDetachHook final : DetachHook {
  void detach_to_bootloader(std::uint16_t) noexcept override { ++calls; }
  int calls = 0;
};

// Kernel speed code for USBDEVFS_GET_SPEED (enum usb_device_speed).
constexpr int kUsbSpeedFull = 2;
// Retries of a synchronous control request (SET_CONFIGURATION, ...) that the
// device NAKs, each after one service(); then ETIMEDOUT.
constexpr int kSyncControlRetries = 1000;

// One transfer in progress on the bus: where it stopped and how it ended.
// `bytes` is the URB buffer (control: 8-byte SETUP + data stage).
struct Transfer {
  std::uint8_t type = USBDEVFS_URB_TYPE_CONTROL;
  EndpointAddress ep = 0;
  unsigned flags = 0;  // USBDEVFS_URB_*
  std::span<std::uint8_t> bytes;
  std::size_t done = 0;  // data bytes moved (control: of the data stage)
  enum class Stage : std::uint8_t { kSetup, kData, kStatus, kFinished } stage = Stage::kSetup;
  bool zlp_sent = false;
  int status = 0;  // the URB's status when finished: 0 or -errno
};

std::uint16_t le16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }

}  // namespace

// Everything the ioctl handler touches. Shared with the GLib closures, so it
// lives until both the fixture and umockdev's handler object are gone.
struct UmockdevUsbDevice::State {
  struct Urb {
    UMockdevIoctlClient* client = nullptr;  // ref
    UMockdevIoctlData* data = nullptr;      // ref: local copy of struct usbdevfs_urb
    UMockdevIoctlData* buffer = nullptr;    // ref or null: local copy of its buffer
    Transfer t;
    usbdevfs_urb* view() const { return reinterpret_cast<usbdevfs_urb*>(data->data); }
  };

  State()
      : storage(flash::stm32f405::kFlashSize),
        flash(flash::stm32f405::kSectors, storage),
        runtime(std::make_unique<firmware::HadynetRuntime<Q>>()),
        link(std::make_unique<link::DeviceLink<Q>>(*runtime)),
        targets{DfuTarget{{flash::stm32f405::kModelSlotBOffset, flash::stm32f405::kModelSlotSize}, true, true},
                DfuTarget{{flash::stm32f405::kModelSlotAOffset, flash::stm32f405::kModelSlotSize}, false, true}},
        usb(std::make_unique<Usb>(controller, *link, flash, targets, hook, kFixtureUid, kFixtureFirmwareVersion)) {
    usb->start();
  }
  ~State() {
    for (auto* q : {&pending, &completed}) {
      for (Urb& u : *q) release(u);
    }
  }
  static void release(Urb& u) {
    if (u.buffer != nullptr) g_object_unref(u.buffer);
    if (u.data != nullptr) g_object_unref(u.data);
    if (u.client != nullptr) g_object_unref(u.client);
    u = Urb{};
  }

  // ---- the bus (caller holds `mutex`) ----

  // Advances `t` as far as the device lets it; true when finished.
  bool advance(Transfer& t) {
    if (t.stage == Transfer::Stage::kFinished) return true;
    if (t.type == USBDEVFS_URB_TYPE_CONTROL) return advance_control(t);
    return is_in(t.ep) ? advance_in(t) : advance_out(t);
  }

  bool finish(Transfer& t, int status) {
    t.status = status;
    t.stage = Transfer::Stage::kFinished;
    return true;
  }

  bool nak() {
    ++stats.naks;
    return false;
  }

  bool advance_control(Transfer& t) {
    const std::uint8_t* s = t.bytes.data();
    const bool in = (s[0] & kRequestDirIn) != 0;
    const std::size_t length = le16(s + 6);
    std::uint8_t packet[kEp0MaxPacket];
    std::size_t n = 0;
    if (t.stage == Transfer::Stage::kSetup) {
      controller.setup_raw(std::span<const std::uint8_t, kSetupPacketSize>(t.bytes.first<kSetupPacketSize>()));
      t.stage = length > 0 ? Transfer::Stage::kData : Transfer::Stage::kStatus;
    }
    std::span<std::uint8_t> data = t.bytes.subspan(kSetupPacketSize, length);
    while (t.stage == Transfer::Stage::kData) {
      if (in) {
        const Handshake h = controller.in_token(in_endpoint(0), packet, n);
        if (h == Handshake::kNak) return nak();
        if (h == Handshake::kStall) return finish(t, -EPIPE);
        if (n > length - t.done) return finish(t, -EOVERFLOW);
        std::memcpy(data.data() + t.done, packet, n);
        t.done += n;
        if (n < kEp0MaxPacket || t.done == length) t.stage = Transfer::Stage::kStatus;
      } else {
        const std::size_t k = std::min(kEp0MaxPacket, length - t.done);
        const Handshake h = controller.out_token(out_endpoint(0), data.subspan(t.done, k));
        if (h == Handshake::kNak) return nak();
        if (h == Handshake::kStall) return finish(t, -EPIPE);
        t.done += k;
        if (t.done == length) t.stage = Transfer::Stage::kStatus;
      }
    }
    // STATUS: the opposite direction, zero length.
    n = 0;
    const Handshake h =
        in && length > 0 ? controller.out_token(out_endpoint(0), {}) : controller.in_token(in_endpoint(0), packet, n);
    if (h == Handshake::kNak) return nak();
    if (h == Handshake::kStall) return finish(t, -EPIPE);
    if (n != 0) return finish(t, -EPROTO);  // data in a status stage
    return finish(t, 0);
  }

  bool advance_in(Transfer& t) {
    const std::size_t max_packet = controller.max_packet(t.ep);
    std::uint8_t packet[64];
    while (true) {
      std::size_t n = 0;
      const Handshake h = controller.in_token(t.ep, packet, n);
      if (h == Handshake::kNak) return nak();
      if (h == Handshake::kStall) return finish(t, -EPIPE);
      if (n > t.bytes.size() - t.done) {  // babble: the packet does not fit
        std::memcpy(t.bytes.data() + t.done, packet, t.bytes.size() - t.done);
        t.done = t.bytes.size();
        return finish(t, -EOVERFLOW);
      }
      std::memcpy(t.bytes.data() + t.done, packet, n);
      t.done += n;
      if (n < max_packet) {
        const bool short_not_ok = (t.flags & USBDEVFS_URB_SHORT_NOT_OK) != 0 && t.done < t.bytes.size();
        return finish(t, short_not_ok ? -EREMOTEIO : 0);
      }
      if (t.done == t.bytes.size()) return finish(t, 0);
    }
  }

  bool advance_out(Transfer& t) {
    const std::size_t max_packet = controller.max_packet(t.ep);
    while (true) {
      const std::size_t k = std::min(max_packet, t.bytes.size() - t.done);
      const bool zlp_wanted =
          t.bytes.empty() || ((t.flags & USBDEVFS_URB_ZERO_PACKET) != 0 && t.bytes.size() % max_packet == 0);
      if (k == 0 && (!zlp_wanted || t.zlp_sent)) return finish(t, 0);
      const Handshake h = controller.out_token(t.ep, t.bytes.subspan(t.done, k));
      if (h == Handshake::kNak) return nak();
      if (h == Handshake::kStall) return finish(t, -EPIPE);
      t.done += k;
      if (k == 0) t.zlp_sent = true;
      if (k < max_packet && k != 0) return finish(t, 0);  // a short packet ends the transfer
    }
  }

  // service(), then every pending URB in submission order; a URB waits while
  // an earlier one on its endpoint is pending. Finished ones move to
  // `completed` (reaped per client, in order).
  void pump() {
    usb->service();
    std::uint32_t blocked = 0;  // bit per endpoint index (number + 16 for IN)
    for (auto it = pending.begin(); it != pending.end();) {
      const std::uint32_t bit = 1u << ((it->t.ep & 0x0F) + (is_in(it->t.ep) ? 16 : 0));
      if ((blocked & bit) != 0 || !advance(it->t)) {
        blocked |= bit;
        ++it;
        continue;
      }
      completed.push_back(*it);
      it = pending.erase(it);
    }
  }

  // A control request the kernel would send itself (SET_CONFIGURATION, ...).
  int sync_control(std::uint8_t request_type, std::uint8_t request, std::uint16_t value, std::uint16_t index) {
    std::uint8_t setup[kSetupPacketSize];
    serialize_setup({request_type, request, value, index, 0}, setup);
    Transfer t;
    t.bytes = setup;
    for (int i = 0; i < kSyncControlRetries; ++i) {
      if (advance(t)) return t.status;
      usb->service();
    }
    return -ETIMEDOUT;
  }

  // Bus reset + SET_ADDRESS + SET_CONFIGURATION(`configuration`), as the
  // kernel's enumeration and USBDEVFS_RESET do.
  int reenumerate() {
    for (auto* q : {&pending, &completed}) {
      for (Urb& u : *q) {
        if (u.t.stage == Transfer::Stage::kFinished) continue;
        u.t.stage = Transfer::Stage::kFinished;
        u.t.status = -ENODEV;
      }
    }
    for (Urb& u : pending) completed.push_back(u);
    pending.clear();
    controller.bus_reset();
    const std::uint8_t std_out = request_type(false, RequestKind::kStandard, Recipient::kDevice);
    if (const int r = sync_control(std_out, request::kSetAddress, devnum, 0); r != 0) return r;
    if (configuration == 0) return 0;
    return sync_control(std_out, request::kSetConfiguration, static_cast<std::uint16_t>(configuration), 0);
  }

  // Whether the configuration descriptor read at enumeration declares
  // alternate `alt` of `interface`.
  bool has_alternate(unsigned interface, unsigned alt) const {
    for (std::size_t i = 0; i + 3 < configuration_descriptor.size() && configuration_descriptor[i] != 0;
         i += configuration_descriptor[i]) {
      const std::uint8_t* d = configuration_descriptor.data() + i;
      if (d[1] == descriptor::kInterface && d[2] == interface && d[3] == alt) return true;
    }
    return false;
  }

  void write_configuration_attribute() const {
    if (configuration_attribute.empty()) return;
    if (FILE* f = std::fopen(configuration_attribute.c_str(), "w")) {
      std::fprintf(f, "%u\n", configuration);
      std::fclose(f);
    }
  }

  std::mutex mutex;
  std::vector<std::uint8_t> storage;
  flash::SimulatedNorFlash flash;
  FakeController controller;
  CountingDetachHook hook;
  std::unique_ptr<firmware::HadynetRuntime<Q>> runtime;
  std::unique_ptr<link::DeviceLink<Q>> link;
  std::array<DfuTarget, composite::kDfuAlternates> targets;
  std::unique_ptr<Usb> usb;

  std::deque<Urb> pending;
  std::deque<Urb> completed;
  UmockdevUsbStats stats;
  std::uint8_t devnum = 0;
  unsigned configuration = 1;
  std::string configuration_attribute;                 // real path of sysfs bConfigurationValue
  std::vector<std::uint8_t> configuration_descriptor;  // as read at enumeration
  // Faults: unplugged = every ioctl but reaping fails with ENODEV; an entry
  // of `faults` completes the next URB on its endpoint with -errno.
  bool unplugged = false;
  std::vector<std::pair<EndpointAddress, int>> faults;
};

namespace {

using State = UmockdevUsbDevice::State;

// Reads the unsigned int (or __u32) an ioctl argument points to.
bool read_uint_arg(UMockdevIoctlData* arg, unsigned& value) {
  UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(unsigned), nullptr);
  if (d == nullptr) return false;
  std::memcpy(&value, d->data, sizeof value);
  g_object_unref(d);
  return true;
}

void complete(UMockdevIoctlClient* client, int result) {
  if (result < 0) {
    umockdev_ioctl_client_complete(client, -1, -result);
  } else {
    umockdev_ioctl_client_complete(client, result, 0);
  }
}

int submit_urb(State& s, UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
  State::Urb u;
  u.data = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_urb), nullptr);
  if (u.data == nullptr) return -EFAULT;
  const usbdevfs_urb* v = u.view();
  const auto length = static_cast<std::size_t>(v->buffer_length < 0 ? 0 : v->buffer_length);
  if (length > 0) {
    u.buffer = umockdev_ioctl_data_resolve(u.data, offsetof(usbdevfs_urb, buffer), length, nullptr);
    if (u.buffer == nullptr) {
      State::release(u);
      return -EFAULT;
    }
  }
  u.t.type = v->type;
  u.t.ep = v->endpoint;
  u.t.flags = v->flags;
  u.t.bytes = std::span<std::uint8_t>(u.buffer != nullptr ? u.buffer->data : nullptr, length);
  u.t.stage = Transfer::Stage::kSetup;
  // The kernel's checks (proc_do_submiturb), as far as they matter here.
  int error = 0;
  switch (u.t.type) {
    case USBDEVFS_URB_TYPE_CONTROL:
      if ((u.t.ep & 0x7F) != 0 || length < kSetupPacketSize || le16(u.t.bytes.data() + 6) > length - kSetupPacketSize) {
        error = -EINVAL;
      }
      break;
    case USBDEVFS_URB_TYPE_BULK:
    case USBDEVFS_URB_TYPE_INTERRUPT:
      if (endpoint_number(u.t.ep) == 0 || !s.controller.endpoint_open(u.t.ep)) {
        error = -ENOENT;
      } else if (u.t.type == USBDEVFS_URB_TYPE_INTERRUPT &&
                 s.controller.endpoint_type(u.t.ep) != EndpointType::kInterrupt) {
        error = -EINVAL;
      }
      break;
    default:  // isochronous: the device has none
      error = -EINVAL;
  }
  if (error != 0) {
    State::release(u);
    return error;
  }
  u.client = UMOCKDEV_IOCTL_CLIENT(g_object_ref(client));
  ++s.stats.urbs_submitted;
  for (auto f = s.faults.begin(); f != s.faults.end(); ++f) {
    if (f->first != u.t.ep) continue;
    u.t.stage = Transfer::Stage::kFinished;  // the device never sees it
    u.t.status = -f->second;
    s.faults.erase(f);
    s.completed.push_back(u);
    return 0;
  }
  s.pending.push_back(u);
  s.pump();
  return 0;
}

int reap_urb(State& s, UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
  if (!s.unplugged) s.pump();
  for (auto it = s.completed.begin(); it != s.completed.end(); ++it) {
    if (it->client != client) continue;
    State::Urb u = *it;
    s.completed.erase(it);
    usbdevfs_urb* v = u.view();
    v->status = u.t.status;
    v->actual_length = static_cast<int>(u.t.done);
    UMockdevIoctlData* ptr = umockdev_ioctl_data_resolve(arg, 0, sizeof(void*), nullptr);
    if (ptr == nullptr) {
      State::release(u);
      return -EFAULT;
    }
    umockdev_ioctl_data_set_ptr(ptr, 0, u.data);  // the client gets its own URB's address back
    g_object_unref(ptr);
    ++s.stats.urbs_reaped;
    State::release(u);  // the reply holds its own references until it is written
    return 0;
  }
  return -EAGAIN;
}

int discard_urb(State& s, UMockdevIoctlClient* client, UMockdevIoctlData* arg) {
  gulong address = 0;
  std::memcpy(&address, arg->data, sizeof address);  // the argument is the URB's address itself
  for (auto it = s.pending.begin(); it != s.pending.end(); ++it) {
    if (it->client != client || it->data->client_addr != address) continue;
    it->t.status = -ENOENT;
    it->t.stage = Transfer::Stage::kFinished;
    s.completed.push_back(*it);
    s.pending.erase(it);
    ++s.stats.urbs_discarded;
    return 0;
  }
  return -EINVAL;  // unknown, or already finished (then it is reaped normally)
}

int handle(State& s, UMockdevIoctlClient* client) {
  const unsigned long request = umockdev_ioctl_client_get_request(client);
  UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
  const std::uint8_t std_out_device = request_type(false, RequestKind::kStandard, Recipient::kDevice);
  ++s.stats.ioctls;
  if (s.unplugged && request != USBDEVFS_REAPURB && request != USBDEVFS_REAPURBNDELAY &&
      request != USBDEVFS_DISCARDURB) {
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
      return submit_urb(s, client, arg);
    case USBDEVFS_REAPURB:  // would block in the kernel; libusb only uses NDELAY
    case USBDEVFS_REAPURBNDELAY:
      return reap_urb(s, client, arg);
    case USBDEVFS_DISCARDURB:
      return discard_urb(s, client, arg);
    case USBDEVFS_CLAIMINTERFACE:
    case USBDEVFS_RELEASEINTERFACE: {
      unsigned interface = 0;
      if (!read_uint_arg(arg, interface)) return -EFAULT;
      return s.configuration != 0 && interface < composite::kInterfaceCount ? 0 : -EINVAL;
    }
    case USBDEVFS_SETINTERFACE: {
      UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_setinterface), nullptr);
      if (d == nullptr) return -EFAULT;
      usbdevfs_setinterface si{};
      std::memcpy(&si, d->data, sizeof si);
      g_object_unref(d);
      if (!s.has_alternate(si.interface, si.altsetting)) return -EINVAL;  // the kernel checks its copy
      return s.sync_control(request_type(false, RequestKind::kStandard, Recipient::kInterface), request::kSetInterface,
                            static_cast<std::uint16_t>(si.altsetting), static_cast<std::uint16_t>(si.interface));
    }
    case USBDEVFS_SETCONFIGURATION: {
      unsigned value = 0;
      if (!read_uint_arg(arg, value)) return -EFAULT;
      const unsigned configuration = static_cast<int>(value) < 0 ? 0 : value;  // -1: unconfigure
      const int r =
          s.sync_control(std_out_device, request::kSetConfiguration, static_cast<std::uint16_t>(configuration), 0);
      if (r == 0) {
        s.configuration = configuration;
        s.write_configuration_attribute();
      }
      return r;
    }
    case USBDEVFS_CLEAR_HALT: {
      unsigned ep = 0;
      if (!read_uint_arg(arg, ep)) return -EFAULT;
      return s.sync_control(request_type(false, RequestKind::kStandard, Recipient::kEndpoint), request::kClearFeature,
                            kFeatureEndpointHalt, static_cast<std::uint16_t>(ep));
    }
    case USBDEVFS_RESETEP:  // host-side toggle only
      return 0;
    case USBDEVFS_RESET:
      return s.reenumerate();
    case USBDEVFS_GETDRIVER:
      return -ENODATA;  // no kernel driver bound to any interface
    case USBDEVFS_IOCTL:
    case USBDEVFS_DISCONNECT_CLAIM:
      return 0;  // detach/attach kernel drivers: there are none
    default:
      ++s.stats.unknown_ioctls;
      s.stats.last_unknown_ioctl = request;
      return -ENOTTY;
  }
}

gboolean on_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer data) {
  State& s = **static_cast<std::shared_ptr<State>*>(data);
  int result = 0;
  {
    const std::lock_guard<std::mutex> lock(s.mutex);
    result = handle(s, client);
  }
  complete(client, result);
  return TRUE;
}

void on_client_vanished(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer data) {
  State& s = **static_cast<std::shared_ptr<State>*>(data);
  const std::lock_guard<std::mutex> lock(s.mutex);
  for (auto* q : {&s.pending, &s.completed}) {
    for (auto it = q->begin(); it != q->end();) {
      if (it->client != client) {
        ++it;
        continue;
      }
      State::release(*it);
      it = q->erase(it);
    }
  }
}

void drop_state_ref(gpointer data, GClosure*) { delete static_cast<std::shared_ptr<State>*>(data); }

// A control IN transfer during enumeration (no URB; the fixture's thread).
std::vector<std::uint8_t> control_in(State& s, std::uint8_t request, std::uint16_t value, std::uint16_t index,
                                     std::uint16_t length, int& status) {
  std::vector<std::uint8_t> bytes(kSetupPacketSize + length);
  serialize_setup({request_type(true, RequestKind::kStandard, Recipient::kDevice), request, value, index, length},
                  std::span<std::uint8_t, kSetupPacketSize>(bytes.data(), kSetupPacketSize));
  Transfer t;
  t.bytes = bytes;
  status = -ETIMEDOUT;
  for (int i = 0; i < kSyncControlRetries; ++i) {
    if (s.advance(t)) {
      status = t.status;
      break;
    }
    s.usb->service();
  }
  return std::vector<std::uint8_t>(bytes.begin() + kSetupPacketSize,
                                   bytes.begin() + static_cast<std::ptrdiff_t>(kSetupPacketSize + t.done));
}

// A string descriptor (LANGID 0x0409) as ASCII; empty if refused.
std::string read_string(State& s, std::uint8_t index) {
  int status = 0;
  const std::vector<std::uint8_t> d = control_in(
      s, request::kGetDescriptor, static_cast<std::uint16_t>((descriptor::kString << 8) | index), 0x0409, 255, status);
  std::string out;
  if (status != 0 || d.size() < 2 || d[1] != descriptor::kString) return out;
  for (std::size_t i = 2; i + 1 < d.size() && i < d[0]; i += 2) out.push_back(static_cast<char>(d[i]));
  return out;
}

std::string hex(const std::vector<std::uint8_t>& bytes) {
  std::string out;
  char b[3];
  for (const std::uint8_t v : bytes) {
    std::snprintf(b, sizeof b, "%02x", v);
    out += b;
  }
  return out;
}

}  // namespace

UmockdevUsbDevice::UmockdevUsbDevice(std::uint8_t busnum, std::uint8_t devnum)
    : busnum_(busnum), devnum_(devnum), state_(std::make_shared<State>()) {
  // The testbed first: umockdev_in_mock_environment() stats /sys (the
  // testbed's under the preload library) and caches the answer.
  auto* testbed = umockdev_testbed_new();
  testbed_ = testbed;
  if (!umockdev_in_mock_environment()) {
    error_ = "not in a umockdev environment: run the test under umockdev-wrapper";
    return;
  }
  State& s = *state_;
  const std::lock_guard<std::mutex> lock(s.mutex);
  s.devnum = devnum;

  // Enumeration, as Linux does it (minus the second reset).
  int status = 0;
  s.controller.bus_reset();
  device_descriptor_ = control_in(s, request::kGetDescriptor, descriptor::kDevice << 8, 0, 18, status);
  if (status != 0 || device_descriptor_.size() != 18) {
    error_ = "GET_DESCRIPTOR(device) failed: status " + std::to_string(status);
    return;
  }
  if (s.sync_control(request_type(false, RequestKind::kStandard, Recipient::kDevice), request::kSetAddress, devnum,
                     0) != 0) {
    error_ = "SET_ADDRESS refused";
    return;
  }
  const std::vector<std::uint8_t> head =
      control_in(s, request::kGetDescriptor, descriptor::kConfiguration << 8, 0, 9, status);
  if (status != 0 || head.size() != 9) {
    error_ = "GET_DESCRIPTOR(configuration, 9) failed";
    return;
  }
  const std::uint16_t total = le16(head.data() + 2);
  configuration_ = control_in(s, request::kGetDescriptor, descriptor::kConfiguration << 8, 0, total, status);
  if (status != 0 || configuration_.size() != total) {
    error_ = "GET_DESCRIPTOR(configuration, wTotalLength) failed";
    return;
  }
  const std::string manufacturer = read_string(s, device_descriptor_[14]);
  const std::string product = read_string(s, device_descriptor_[15]);
  const std::string serial = read_string(s, device_descriptor_[16]);
  const std::string configuration_name = read_string(s, configuration_[6]);
  const std::uint8_t configuration_value = configuration_[5];
  if (s.sync_control(request_type(false, RequestKind::kStandard, Recipient::kDevice), request::kSetConfiguration,
                     configuration_value, 0) != 0) {
    error_ = "SET_CONFIGURATION refused";
    return;
  }
  s.configuration = configuration_value;
  s.configuration_descriptor = configuration_;

  auto* handler = umockdev_ioctl_base_new();
  handler_ = handler;
  g_signal_connect_data(handler, "handle-ioctl", G_CALLBACK(on_ioctl), new std::shared_ptr<State>(state_),
                        drop_state_ref, GConnectFlags{});
  g_signal_connect_data(handler, "client-vanished", G_CALLBACK(on_client_vanished), new std::shared_ptr<State>(state_),
                        drop_state_ref, GConnectFlags{});
  GError* gerror = nullptr;
  if (!umockdev_testbed_attach_ioctl(testbed, devnode().c_str(), handler, &gerror)) {
    error_ = std::string("umockdev_testbed_attach_ioctl: ") + (gerror != nullptr ? gerror->message : "?");
    g_clear_error(&gerror);
    return;
  }

  // The device as `umockdev-record` would write it (kernel attribute
  // formats: hex without 0x for ids and classes, "%2d" for bNumInterfaces).
  char bus[4], dev[4];
  std::snprintf(bus, sizeof bus, "%03u", busnum);
  std::snprintf(dev, sizeof dev, "%03u", devnum);
  const std::string sysname = std::to_string(busnum) + "-1";
  const std::uint8_t* d = device_descriptor_.data();
  char ids[160];
  std::snprintf(ids, sizeof ids,
                "A: idVendor=%04x\\n\nA: idProduct=%04x\\n\nA: bcdDevice=%04x\\n\nA: bDeviceClass=%02x\\n\n"
                "A: bDeviceSubClass=%02x\\n\nA: bDeviceProtocol=%02x\\n\n",
                le16(d + 8), le16(d + 10), le16(d + 12), d[4], d[5], d[6]);
  char config[200];
  std::snprintf(config, sizeof config,
                "A: bConfigurationValue=%u\\n\nA: bNumConfigurations=%u\\n\nA: bNumInterfaces=%2u\\n\n"
                "A: bmAttributes=%02x\\n\nA: MaxPower=%umA\\n\nA: bMaxPacketSize0=%u\\n\n",
                configuration_value, d[17], configuration_[4], configuration_[7], configuration_[8] * 2u, d[7]);
  std::vector<std::uint8_t> descriptors = device_descriptor_;
  descriptors.insert(descriptors.end(), configuration_.begin(), configuration_.end());
  const std::string record =
      "P: /devices/pci0000:00/0000:00:14.0/usb" + std::to_string(busnum) + "/" + sysname + "\n" +     //
      "N: bus/usb/" + bus + "/" + dev + "\n" +                                                        //
      "E: SUBSYSTEM=usb\nE: DEVTYPE=usb_device\nE: DRIVER=usb\n" +                                    //
      "E: BUSNUM=" + bus + "\nE: DEVNUM=" + dev + "\nE: DEVNAME=" + devnode() + "\n" +                //
      "A: busnum=" + std::to_string(busnum) + "\\n\nA: devnum=" + std::to_string(devnum) + "\\n\n" +  //
      "A: devpath=1\\n\nA: speed=12\\n\nA: version= 2.00\\n\nA: maxchild=0\\n\n" + ids + config +     //
      "A: manufacturer=" + manufacturer + "\\n\nA: product=" + product + "\\n\nA: serial=" + serial +
      "\\n\nA: configuration=" + configuration_name + "\\n\n" +  //
      "H: descriptors=" + hex(descriptors) + "\n";
  syspath_ = "/sys/devices/pci0000:00/0000:00:14.0/usb" + std::to_string(busnum) + "/" + sysname;
  if (!umockdev_testbed_add_from_string(testbed, record.c_str(), &gerror)) {
    error_ = std::string("umockdev_testbed_add_from_string: ") + (gerror != nullptr ? gerror->message : "?");
    g_clear_error(&gerror);
    return;
  }
  gchar* sys_dir = umockdev_testbed_get_sys_dir(testbed);
  s.configuration_attribute = std::string(sys_dir) + syspath_.substr(4) + "/bConfigurationValue";
  g_free(sys_dir);
}

UmockdevUsbDevice::~UmockdevUsbDevice() {
  if (testbed_ != nullptr) g_object_unref(static_cast<UMockdevTestbed*>(testbed_));
  // The handler may still be referenced by umockdev's worker; its closures
  // hold the state until it is finalised.
  if (handler_ != nullptr) g_object_unref(static_cast<UMockdevIoctlBase*>(handler_));
}

std::string UmockdevUsbDevice::devnode() const {
  char path[32];
  std::snprintf(path, sizeof path, "/dev/bus/usb/%03u/%03u", busnum_, devnum_);
  return path;
}

std::string UmockdevUsbDevice::serial_number() const {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->usb->serial_number();
}

std::string UmockdevUsbDevice::version_string() const {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->usb->version();
}

void UmockdevUsbDevice::publish(const app::PeriodRecord<Q>& record) {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  state_->usb->publish(record);
  state_->pump();
}

void UmockdevUsbDevice::pump() {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  state_->pump();
}

UmockdevUsbStats UmockdevUsbDevice::stats() const {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->stats;
}

int UmockdevUsbDevice::detach_requests() const {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->hook.calls;
}

void UmockdevUsbDevice::fail_next_transfer(std::uint8_t endpoint, int error_number) {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  state_->faults.emplace_back(endpoint, error_number);
}

void UmockdevUsbDevice::unplug() {
  {
    const std::lock_guard<std::mutex> lock(state_->mutex);
    State& s = *state_;
    if (s.unplugged) return;
    s.unplugged = true;
    for (State::Urb& u : s.pending) {
      u.t.stage = Transfer::Stage::kFinished;
      u.t.status = -ENODEV;
      s.completed.push_back(u);
    }
    s.pending.clear();
  }
  if (testbed_ != nullptr && !syspath_.empty()) {
    umockdev_testbed_remove_device(static_cast<UMockdevTestbed*>(testbed_), syspath_.c_str());  // "remove" uevent
  }
}

}  // namespace hadynet::usb::host_testing
