#include "test/usb_host/usb_testbed.h"

#include <sys/stat.h>
#include <umockdev.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "test/usb_host/cdc_tty_bridge.h"
#include "test/usb_host/usbdevfs_node.h"

namespace hadynet::usb::host_testing {

// A node and the lock, as umockdev's handler closures hold them: they live
// until both the testbed and umockdev's handler object are gone.
struct NodeBinding {
  std::shared_ptr<std::mutex> lock;
  std::shared_ptr<UsbdevfsNode> node;
};

struct UsbTestbed::Bus {
  std::shared_ptr<std::mutex> lock = std::make_shared<std::mutex>();
  struct Entry {
    std::shared_ptr<UsbdevfsNode> node;
    UMockdevIoctlBase* handler = nullptr;  // ref
    bool unplugged_by_test = false;
    // Left and removed from sysfs; the node stays attached (answering
    // ENODEV, as the kernel does to clients that still hold it open) until
    // the address is reused or the testbed goes.
    bool removed = false;
  };
  std::map<std::uint8_t, Entry> nodes;  // guarded by *lock
  std::function<void(std::uint8_t)> on_left;
};

namespace {

gboolean on_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer data) {
  NodeBinding& b = *static_cast<NodeBinding*>(data);
  int result = 0;
  {
    const std::lock_guard<std::mutex> lock(*b.lock);
    result = b.node->handle(client);
  }
  if (result < 0) {
    umockdev_ioctl_client_complete(client, -1, -result);
  } else {
    umockdev_ioctl_client_complete(client, result, 0);
  }
  return TRUE;
}

void on_client_vanished(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer data) {
  NodeBinding& b = *static_cast<NodeBinding*>(data);
  const std::lock_guard<std::mutex> lock(*b.lock);
  b.node->client_vanished(client);
}

void drop_binding(gpointer data, GClosure*) { delete static_cast<NodeBinding*>(data); }

std::string gerror_text(const char* what, GError*& e) {
  std::string s = std::string(what) + ": " + (e != nullptr ? e->message : "?");
  g_clear_error(&e);
  return s;
}

}  // namespace

UsbTestbed::UsbTestbed() : bus_(std::make_shared<Bus>()) {
  // The testbed first: umockdev_in_mock_environment() stats /sys (the
  // testbed's under the preload library) and caches the answer.
  auto* testbed = umockdev_testbed_new();
  testbed_ = testbed;
  if (!umockdev_in_mock_environment()) {
    error_ = "not in a umockdev environment: run the test under umockdev-wrapper";
    return;
  }
  // libusb's Linux backend refuses to start without a usbfs directory, which
  // a real system always has (root hubs).
  gchar* root = umockdev_testbed_get_root_dir(testbed);
  const std::string dev = std::string(root) + "/dev";
  g_free(root);
  for (const std::string& d : {dev, dev + "/bus", dev + "/bus/usb"}) ::mkdir(d.c_str(), 0755);
}

UsbTestbed::~UsbTestbed() {
  std::map<std::uint8_t, Bus::Entry> nodes;
  {
    const std::lock_guard<std::mutex> lock(*bus_->lock);
    nodes.swap(bus_->nodes);
  }
  // The handlers may still be referenced by umockdev's worker; their
  // closures hold the nodes until they are finalised.
  for (auto& [devnum, e] : nodes) g_object_unref(e.handler);
  if (testbed_ != nullptr) g_object_unref(static_cast<UMockdevTestbed*>(testbed_));
}

bool UsbTestbed::plug(std::uint8_t devnum, std::shared_ptr<EmulatedDevice> device) {
  auto* testbed = static_cast<UMockdevTestbed*>(testbed_);
  if (!ok() && error_.rfind("not in a umockdev", 0) == 0) return false;
  error_.clear();
  if (devnum < 2 || devnum > 127 || device == nullptr) {
    error_ = "plug: address " + std::to_string(devnum) + " is not 2..127 or no device";
    return false;
  }
  std::shared_ptr<UsbdevfsNode> node;
  UMockdevIoctlBase* retired = nullptr;
  {
    const std::lock_guard<std::mutex> lock(*bus_->lock);
    if (const auto it = bus_->nodes.find(devnum); it != bus_->nodes.end()) {
      if (!it->second.removed) {
        error_ = "plug: address " + std::to_string(devnum) + " is taken";
        return false;
      }
      retired = it->second.handler;
      bus_->nodes.erase(it);
    }
    UrbEngine engine(*device);
    EnumeratedDevice enumerated;
    if (std::string e = enumerate(engine, kBusnum, devnum, enumerated); !e.empty()) {
      error_ = "enumeration of device " + std::to_string(devnum) + ": " + e;
      return false;
    }
    node = std::make_shared<UsbdevfsNode>(std::move(device), std::move(enumerated));
  }
  // umockdev calls without the bus lock: its worker may be waiting for it.
  const EnumeratedDevice& en = node->enumerated();
  if (retired != nullptr) {
    umockdev_testbed_detach_ioctl(testbed, en.devnode().c_str(), nullptr);
    g_object_unref(retired);
  }
  auto* handler = umockdev_ioctl_base_new();
  g_signal_connect_data(handler, "handle-ioctl", G_CALLBACK(on_ioctl), new NodeBinding{bus_->lock, node},
                        drop_binding, GConnectFlags{});
  g_signal_connect_data(handler, "client-vanished", G_CALLBACK(on_client_vanished), new NodeBinding{bus_->lock, node},
                        drop_binding, GConnectFlags{});
  GError* gerror = nullptr;
  if (!umockdev_testbed_attach_ioctl(testbed, en.devnode().c_str(), handler, &gerror)) {
    error_ = gerror_text("umockdev_testbed_attach_ioctl", gerror);
    g_object_unref(handler);
    return false;
  }
  if (!umockdev_testbed_add_from_string(testbed, sysfs_record(en).c_str(), &gerror)) {
    error_ = gerror_text("umockdev_testbed_add_from_string", gerror);
    umockdev_testbed_detach_ioctl(testbed, en.devnode().c_str(), nullptr);
    g_object_unref(handler);
    return false;
  }
  gchar* sys_dir = umockdev_testbed_get_sys_dir(testbed);
  const std::string attribute = std::string(sys_dir) + en.syspath().substr(4) + "/bConfigurationValue";
  g_free(sys_dir);
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  node->set_configuration_attribute(attribute);
  bus_->nodes[devnum] = Bus::Entry{node, handler, false, false};
  return true;
}

void UsbTestbed::unplug(std::uint8_t devnum) {
  {
    const std::lock_guard<std::mutex> lock(*bus_->lock);
    const auto it = bus_->nodes.find(devnum);
    if (it == bus_->nodes.end() || it->second.removed) return;
    it->second.node->leave();
    it->second.unplugged_by_test = true;
  }
  pump();  // the removal
}

bool UsbTestbed::plugged(std::uint8_t devnum) const {
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  const auto it = bus_->nodes.find(devnum);
  return it != bus_->nodes.end() && !it->second.removed && !it->second.node->left();
}

EnumeratedDevice UsbTestbed::enumerated(std::uint8_t devnum) const {
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  const auto it = bus_->nodes.find(devnum);
  return it == bus_->nodes.end() ? EnumeratedDevice{} : it->second.node->enumerated();
}

void UsbTestbed::pump() {
  std::vector<std::pair<std::uint8_t, Bus::Entry>> gone;
  {
    const std::lock_guard<std::mutex> lock(*bus_->lock);
    for (auto& [devnum, e] : bus_->nodes) {
      if (e.removed || e.node->pump()) continue;
      e.removed = true;
      gone.emplace_back(devnum, e);
    }
  }
  auto* testbed = static_cast<UMockdevTestbed*>(testbed_);
  for (auto& [devnum, e] : gone) {
    umockdev_testbed_remove_device(testbed, e.node->enumerated().syspath().c_str());  // a "remove" uevent
  }
  for (auto& [devnum, e] : gone) {
    if (!e.unplugged_by_test && bus_->on_left) bus_->on_left(devnum);
  }
}

void UsbTestbed::locked(const std::function<void()>& fn) {
  {
    const std::lock_guard<std::mutex> lock(*bus_->lock);
    fn();
  }
  pump();
}

void UsbTestbed::set_on_left(std::function<void(std::uint8_t devnum)> on_left) {
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  bus_->on_left = std::move(on_left);
}

void UsbTestbed::fail_next_transfer(std::uint8_t devnum, std::uint8_t endpoint, int error_number) {
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  if (const auto it = bus_->nodes.find(devnum); it != bus_->nodes.end()) {
    it->second.node->engine().add_fault({endpoint, InjectedFault::Kind::kError, error_number, 0});
  }
}

void UsbTestbed::short_next_in(std::uint8_t devnum, std::uint8_t endpoint, std::size_t bytes) {
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  if (const auto it = bus_->nodes.find(devnum); it != bus_->nodes.end()) {
    it->second.node->engine().add_fault({endpoint, InjectedFault::Kind::kShortPacket, 0, bytes});
  }
}

void UsbTestbed::hang_next_transfer(std::uint8_t devnum, std::uint8_t endpoint) {
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  if (const auto it = bus_->nodes.find(devnum); it != bus_->nodes.end()) {
    it->second.node->engine().add_fault({endpoint, InjectedFault::Kind::kTimeout, 0, 0});
  }
}

std::string UsbTestbed::attach_cdc_tty(std::uint8_t devnum, const std::string& tty_name, std::uint8_t out_ep,
                                       std::uint8_t in_ep) {
  std::string slave, failure;
  std::unique_ptr<CdcTtyBridge> bridge = CdcTtyBridge::open(out_ep, in_ep, slave, failure);
  if (bridge == nullptr) {
    error_ = "attach_cdc_tty: " + failure;
    return "";
  }
  // /dev/<tty_name> in the testbed: a link to the pty's slave.
  gchar* root = umockdev_testbed_get_root_dir(static_cast<UMockdevTestbed*>(testbed_));
  const std::string link = std::string(root) + "/dev/" + tty_name;
  g_free(root);
  if (::symlink(slave.c_str(), link.c_str()) != 0) {
    error_ = "attach_cdc_tty: symlink " + link + ": " + std::strerror(errno);
    return "";
  }
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  const auto it = bus_->nodes.find(devnum);
  if (it == bus_->nodes.end()) {
    error_ = "attach_cdc_tty: no device at " + std::to_string(devnum);
    return "";
  }
  it->second.node->set_bridge(std::move(bridge));
  return "/dev/" + tty_name;
}

UsbNodeStats UsbTestbed::stats(std::uint8_t devnum) const {
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  const auto it = bus_->nodes.find(devnum);
  return it == bus_->nodes.end() ? UsbNodeStats{} : it->second.node->stats();
}

PacketCounts UsbTestbed::packets(std::uint8_t devnum) const {
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  const auto it = bus_->nodes.find(devnum);
  return it == bus_->nodes.end() ? PacketCounts{} : it->second.node->engine().packets();
}

bool UsbTestbed::has_pending(std::uint8_t devnum, std::uint8_t endpoint) const {
  const std::lock_guard<std::mutex> lock(*bus_->lock);
  const auto it = bus_->nodes.find(devnum);
  return it != bus_->nodes.end() && it->second.node->has_pending(endpoint);
}

}  // namespace hadynet::usb::host_testing
