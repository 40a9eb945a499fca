// A device for the model-slot tests: a SimulatedNorFlash with a sector
// table and two slots, the ModelSlots of the current power-on session
// (reboot() = RAM lost, a new ModelSlots over the same flash), a
// scriptable self-test and helpers to stream images.
#ifndef HADYNET_TEST_MODEL_UPDATE_SLOT_TEST_DEVICE_H_
#define HADYNET_TEST_MODEL_UPDATE_SLOT_TEST_DEVICE_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "firmware/flash/simulated_nor_flash.h"
#include "firmware/model_update/model_slots.h"
#include "test/model_update/signed_images.h"

namespace hadynet::model_update::test {

struct SlotLayout {
  std::span<const flash::FlashSector> sectors;
  flash::FlashRegion slot_a{};
  flash::FlashRegion slot_b{};
  std::uint32_t alignment = 4;  // program unit, bytes
};

// 6 sectors of 4 KiB: 0..1 "firmware", slot A = 2..3, slot B = 4..5 (8 KiB each).
SlotLayout small_layout();
// The STM32F405's table and its model slots (stm32f405_flash_layout.h).
SlotLayout stm32f405_layout();

// The small layout's model: 6000 payload bytes (spans both sectors of a slot).
ModelIdentity small_identity();
// The key the test devices trust, and another one.
const SigningKey& device_key();
const SigningKey& other_key();

class ScriptedSelfTest final : public SelfTest {
 public:
  explicit ScriptedSelfTest(bool pass_verdict = true) : pass(pass_verdict) {}
  bool run(std::span<const std::uint8_t> payload, const ModelImageHeader& header) noexcept override;

  bool pass;
  int calls = 0;
  Bytes last_payload;
  std::uint32_t last_self_test_checksum = 0;
  std::function<void()> during_run;  // called inside run(), before the verdict
};

class SlotTestDevice {
 public:
  SlotTestDevice(const SlotLayout& layout, const ModelIdentity& identity);
  // A device whose flash holds `contents` (a snapshot of another's cells);
  // its operation count starts at 0, power on.
  SlotTestDevice(const SlotLayout& layout, const ModelIdentity& identity, const Bytes& contents);
  SlotTestDevice(const SlotTestDevice&) = delete;  // the flash and the slots point into it
  SlotTestDevice& operator=(const SlotTestDevice&) = delete;

  flash::SimulatedNorFlash& nor() { return nor_; }
  const Bytes& cells() const { return cells_; }
  // The cells themselves, to corrupt them behind the flash's back (bit rot).
  Bytes& raw_cells() { return cells_; }
  ModelSlots& slots() { return *slots_; }
  // Power-on reset: a new ModelSlots (RAM state lost) over the same flash.
  ModelSlots& reboot();
  BootChoice reboot_and_boot(SelfTest& self_test);
  BootChoice reboot_and_boot(bool self_test_passes = true);

  Bytes slot_bytes(SlotId slot) const;
  const flash::FlashRegion& region(SlotId slot) const { return slot == SlotId::kA ? layout_.slot_a : layout_.slot_b; }

 private:
  SlotLayout layout_;
  ModelIdentity identity_;
  Bytes cells_;
  flash::SimulatedNorFlash nor_;
  std::unique_ptr<ModelSlots> slots_;
};

// `cells` with the bytes of `slot` set to 0 (to compare "everything else").
Bytes cells_without(const Bytes& cells, const flash::FlashRegion& slot);

// The default chunking of a stream: odd sizes, cycled.
inline constexpr std::size_t kDefaultChunks[] = {256, 1, 700, 31, 1024, 255, 513};

// begin(header), append(payload in chunks cycling through `chunks`),
// finish(); the first error (kOk if none). Stops at the first error.
UpdateError write_image(ModelSlots& slots, const Bytes& image,
                        std::span<const std::size_t> chunks = kDefaultChunks);

// Streams `image` in the current session (booting it first, self-test
// passing, if it has not booted), then reboots and boots with the given
// self-test verdict. The stream's result in `written` (if not null).
BootChoice install(SlotTestDevice& device, const Bytes& image, bool self_test_passes = true,
                   UpdateError* written = nullptr);

// The small layout's flash with image 1 (payload seed 10) in A and image 2
// (seed 20) in B, both confirmed: B is in use, updates target A. Made once.
const Bytes& two_confirmed_images();

// An image of the small identity with `sequence` and a payload from `seed`.
Bytes small_image(std::uint32_t sequence, std::uint32_t payload_seed);

}  // namespace hadynet::model_update::test

#endif  // HADYNET_TEST_MODEL_UPDATE_SLOT_TEST_DEVICE_H_
