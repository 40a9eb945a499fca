#include "test/usb_host/hand_device.h"

#include <vector>

#include "firmware/app/model_store.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/flash/simulated_nor_flash.h"
#include "firmware/flash/stm32f405_flash_layout.h"
#include "firmware/link/device_link.h"
#include "firmware/link/frame.h"
#include "firmware/model_update/model_slots.h"
#include "firmware/usb/hadynet_usb_device.h"
#include "firmware/usb/host/fake_controller.h"
#include "host-sim/model_image/signing_key.h"

#ifndef HADYNET_DEVELOPMENT_PUBLIC_KEY_FILE
#error "the build defines HADYNET_DEVELOPMENT_PUBLIC_KEY_FILE (keys/development.key.pub)"
#endif

namespace hadynet::usb::host_testing {
namespace {

using Usb = HadynetUsbDevice<Q, link::DeviceLink<Q>, link::kMaxWireFrame>;
namespace layout = flash::stm32f405;

// The F405's sectors with 1 % of their worst-case erase times.
constexpr std::array<flash::FlashSector, layout::kSectors.size()> scaled_sectors() {
  std::array<flash::FlashSector, layout::kSectors.size()> s{};
  for (std::size_t i = 0; i < s.size(); ++i) {
    s[i] = layout::kSectors[i];
    s[i].erase_max_ms = layout::kSectors[i].erase_max_ms / 100;
  }
  return s;
}
constexpr auto kScaledSectors = scaled_sectors();
constexpr std::uint32_t kScaledProgramUsPerByte = 1;

const model_update::PublicKey& development_key() {
  static const model_update::PublicKey key = hadynet::host::read_public_key(HADYNET_DEVELOPMENT_PUBLIC_KEY_FILE);
  return key;
}

struct ForwardingDetachHook final : DetachHook {
  explicit ForwardingDetachHook(std::function<void(std::uint16_t)> f) : forward(std::move(f)) {}
  void detach_to_bootloader(std::uint16_t timeout_ms) noexcept override { forward(timeout_ms); }
  std::function<void(std::uint16_t)> forward;
};

}  // namespace

struct HandDevice::Parts {
  Parts(HandDevice& owner, const std::vector<std::uint8_t>* cells, bool model_slots)
      : storage(layout::kFlashSize),
        flash(kScaledSectors, storage, layout::kProgramAlignment, kScaledProgramUsPerByte),
        hook([&owner](std::uint16_t t) { owner.detached(t); }),
        runtime(std::make_unique<firmware::HadynetRuntime<Q>>()),
        link(std::make_unique<link::DeviceLink<Q>>(*runtime)) {
    if (cells != nullptr) std::copy(cells->begin(), cells->end(), storage.begin());
    if (model_slots) {
      slots = std::make_unique<model_update::ModelSlots>(
          flash, flash::FlashRegion{layout::kModelSlotAOffset, layout::kModelSlotSize},
          flash::FlashRegion{layout::kModelSlotBOffset, layout::kModelSlotSize}, app::model_identity<Q>(),
          development_key(), flash.contents());
      app::boot_model(*slots, *runtime);  // as firmware_main.cc, before usb_start()
    }
    usb = std::make_unique<Usb>(controller, *link, ModelSlotsAccess{slots.get(), slots ? &flash : nullptr}, hook,
                                kFixtureUid, kFixtureFirmwareVersion);
  }

  std::vector<std::uint8_t> storage;
  flash::SimulatedNorFlash flash;
  host::FakeController controller;
  ForwardingDetachHook hook;
  std::unique_ptr<firmware::HadynetRuntime<Q>> runtime;
  std::unique_ptr<link::DeviceLink<Q>> link;
  std::unique_ptr<model_update::ModelSlots> slots;
  std::unique_ptr<Usb> usb;
};

HandDevice::HandDevice(const std::vector<std::uint8_t>* cells, bool model_slots)
    : parts_(std::make_unique<Parts>(*this, cells, model_slots)) {
  parts_->usb->start();
}
HandDevice::~HandDevice() = default;

host::FakeController& HandDevice::controller() noexcept { return parts_->controller; }
void HandDevice::service() noexcept { parts_->usb->service(); }

void HandDevice::publish(const app::PeriodRecord<Q>& record) { parts_->usb->publish(record); }
std::string HandDevice::serial_number() const { return parts_->usb->serial_number(); }
std::string HandDevice::version_string() const { return parts_->usb->version(); }
model_update::BootChoice HandDevice::boot_choice() const {
  return parts_->slots ? parts_->slots->choice() : model_update::BootChoice{};
}
model_update::SlotStatus HandDevice::slot_status(model_update::SlotId slot) const {
  return parts_->slots ? parts_->slots->slot_status(slot) : model_update::SlotStatus{};
}
std::vector<std::uint8_t> HandDevice::flash_cells() const {
  return std::vector<std::uint8_t>(parts_->flash.contents().begin(), parts_->flash.contents().end());
}

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
