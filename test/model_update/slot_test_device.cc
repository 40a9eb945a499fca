#include "test/model_update/slot_test_device.h"

#include <algorithm>

#include "firmware/flash/stm32f405_flash_layout.h"

namespace hadynet::model_update::test {

namespace {

constexpr std::uint32_t kSmallSector = 4096;
constexpr flash::FlashSector kSmallSectors[] = {
    {0 * kSmallSector, kSmallSector, 40}, {1 * kSmallSector, kSmallSector, 40},
    {2 * kSmallSector, kSmallSector, 40}, {3 * kSmallSector, kSmallSector, 40},
    {4 * kSmallSector, kSmallSector, 40}, {5 * kSmallSector, kSmallSector, 40},
};

std::uint32_t device_size(const SlotLayout& layout) {
  return layout.sectors.back().offset + layout.sectors.back().size;
}

}  // namespace

SlotLayout small_layout() {
  return SlotLayout{kSmallSectors, {2 * kSmallSector, 2 * kSmallSector}, {4 * kSmallSector, 2 * kSmallSector}, 4};
}

SlotLayout stm32f405_layout() {
  namespace f405 = flash::stm32f405;
  return SlotLayout{f405::kSectors,
                    {f405::kModelSlotAOffset, f405::kModelSlotSize},
                    {f405::kModelSlotBOffset, f405::kModelSlotSize},
                    f405::kProgramAlignment};
}

ModelIdentity small_identity() { return ModelIdentity{3, kNumericQ15, 0x5EED5EEDF00DBA11ull, 6000}; }

const SigningKey& device_key() {
  static const SigningKey key = signing_key(0x11);
  return key;
}

const SigningKey& other_key() {
  static const SigningKey key = signing_key(0x22);
  return key;
}

bool ScriptedSelfTest::run(std::span<const std::uint8_t> payload, const ModelImageHeader& header) noexcept {
  ++calls;
  last_payload.assign(payload.begin(), payload.end());
  last_self_test_checksum = header.self_test_checksum;
  if (during_run) during_run();
  return pass;
}

SlotTestDevice::SlotTestDevice(const SlotLayout& layout, const ModelIdentity& identity)
    : layout_(layout),
      identity_(identity),
      cells_(device_size(layout)),
      nor_(layout.sectors, cells_, layout.alignment) {
  reboot();
}

SlotTestDevice::SlotTestDevice(const SlotLayout& layout, const ModelIdentity& identity, const Bytes& contents)
    : SlotTestDevice(layout, identity) {
  std::copy(contents.begin(), contents.end(), cells_.begin());  // same buffer: nor_ sees it
}

ModelSlots& SlotTestDevice::reboot() {
  slots_ = std::make_unique<ModelSlots>(nor_, layout_.slot_a, layout_.slot_b, identity_,
                                        std::span<const std::uint8_t, kPublicKeyBytes>(device_key().public_key),
                                        nor_.contents());
  return *slots_;
}

BootChoice SlotTestDevice::reboot_and_boot(SelfTest& self_test) { return reboot().boot(self_test); }

BootChoice SlotTestDevice::reboot_and_boot(bool self_test_passes) {
  ScriptedSelfTest test(self_test_passes);
  return reboot_and_boot(test);
}

Bytes SlotTestDevice::slot_bytes(SlotId slot) const {
  const flash::FlashRegion& r = region(slot);
  return Bytes(cells_.begin() + r.offset, cells_.begin() + r.offset + r.size);
}

Bytes cells_without(const Bytes& cells, const flash::FlashRegion& slot) {
  Bytes out = cells;
  std::fill(out.begin() + slot.offset, out.begin() + slot.offset + slot.size, std::uint8_t{0});
  return out;
}

UpdateError write_image(ModelSlots& slots, const Bytes& image, std::span<const std::size_t> chunks) {
  UpdateError e = slots.begin_update(header_of(image));
  if (e != UpdateError::kOk) return e;
  const std::span<const std::uint8_t> payload = payload_of(image);
  std::size_t done = 0;
  for (std::size_t k = 0; done < payload.size(); ++k) {
    const std::size_t n = std::min(chunks[k % chunks.size()], payload.size() - done);
    e = slots.append_update(payload.subspan(done, n));
    if (e != UpdateError::kOk) return e;
    done += n;
  }
  return slots.finish_update();
}

BootChoice install(SlotTestDevice& device, const Bytes& image, bool self_test_passes, UpdateError* written) {
  if (!device.slots().booted()) {
    ScriptedSelfTest pass(true);
    device.slots().boot(pass);
  }
  const UpdateError e = write_image(device.slots(), image);
  if (written != nullptr) *written = e;
  return device.reboot_and_boot(self_test_passes);
}

const Bytes& two_confirmed_images() {
  static const Bytes cells = [] {
    SlotTestDevice d(small_layout(), small_identity());
    install(d, small_image(1, 10));
    install(d, small_image(2, 20));
    return d.cells();
  }();
  return cells;
}

Bytes small_image(std::uint32_t sequence, std::uint32_t payload_seed) {
  const ModelIdentity id = small_identity();
  return sign_image(header_for(id, sequence), random_bytes(id.payload_length, payload_seed), device_key());
}

}  // namespace hadynet::model_update::test
