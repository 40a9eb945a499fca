#include "test/usb_host/hand_device.h"

#include <vector>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/flash/simulated_nor_flash.h"
#include "firmware/flash/stm32f405_flash_layout.h"
#include "firmware/link/device_link.h"
#include "firmware/link/frame.h"
#include "firmware/usb/hadynet_usb_device.h"
#include "firmware/usb/host/fake_controller.h"

namespace hadynet::usb::host_testing {
namespace {

using Usb = HadynetUsbDevice<Q, link::DeviceLink<Q>, link::kMaxWireFrame>;

struct ForwardingDetachHook final : DetachHook {
  explicit ForwardingDetachHook(std::function<void(std::uint16_t)> f) : forward(std::move(f)) {}
  void detach_to_bootloader(std::uint16_t timeout_ms) noexcept override { forward(timeout_ms); }
  std::function<void(std::uint16_t)> forward;
};

}  // namespace

struct HandDevice::Parts {
  explicit Parts(HandDevice& owner)
      : storage(flash::stm32f405::kFlashSize),
        flash(flash::stm32f405::kSectors, storage),
        hook([&owner](std::uint16_t t) { owner.detached(t); }),
        runtime(std::make_unique<firmware::HadynetRuntime<Q>>()),
        link(std::make_unique<link::DeviceLink<Q>>(*runtime)),
        // alt 0: the inactive slot (B), writable; alt 1: the active slot (A), read only.
        targets{DfuTarget{{flash::stm32f405::kModelSlotBOffset, flash::stm32f405::kModelSlotSize}, true, true},
                DfuTarget{{flash::stm32f405::kModelSlotAOffset, flash::stm32f405::kModelSlotSize}, false, true}},
        usb(std::make_unique<Usb>(controller, *link, flash, targets, hook, kFixtureUid, kFixtureFirmwareVersion)) {}

  std::vector<std::uint8_t> storage;
  flash::SimulatedNorFlash flash;
  host::FakeController controller;
  ForwardingDetachHook hook;
  std::unique_ptr<firmware::HadynetRuntime<Q>> runtime;
  std::unique_ptr<link::DeviceLink<Q>> link;
  std::array<DfuTarget, composite::kDfuAlternates> targets;
  std::unique_ptr<Usb> usb;
};

HandDevice::HandDevice() : parts_(std::make_unique<Parts>(*this)) { parts_->usb->start(); }
HandDevice::~HandDevice() = default;

host::FakeController& HandDevice::controller() noexcept { return parts_->controller; }
void HandDevice::service() noexcept { parts_->usb->service(); }

void HandDevice::publish(const app::PeriodRecord<Q>& record) { parts_->usb->publish(record); }
std::string HandDevice::serial_number() const { return parts_->usb->serial_number(); }
std::string HandDevice::version_string() const { return parts_->usb->version(); }

void HandDevice::detached(std::uint16_t timeout_ms) noexcept {
  ++detach_requests_;
  last_detach_timeout_ms_ = timeout_ms;
  if (on_detach_) on_detach_(timeout_ms);
  if (leave_on_detach_) {
    attached_ = false;
    parts_->controller.set_connected(false);  // the reset drops the pull-up
  }
}

}  // namespace hadynet::usb::host_testing
