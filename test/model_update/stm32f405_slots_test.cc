// The model slots on the STM32F405's real sector table and slot offsets
// (firmware/flash/stm32f405_flash_layout.h): slots A = sectors 8..9 at
// 0x80000, B = sectors 10..11 at 0xC0000, 256 KiB each, 128 KiB sectors.
#include <gtest/gtest.h>

#include "firmware/flash/stm32f405_flash_layout.h"
#include "firmware/model_update/slot_layout.h"
#include "test/model_update/power_cut_harness.h"

namespace hadynet::model_update::test {
namespace {

namespace f405 = flash::stm32f405;

// A model of 150 000 payload bytes: header + payload span both sectors of a slot.
ModelIdentity f405_identity() { return ModelIdentity{3, kNumericQ15, 0x0123456789ABCDEFull, 150000}; }

Bytes as_bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }

constexpr std::size_t kDfuBlocks[] = {256};       // what DFU delivers
constexpr std::size_t kLargeChunks[] = {16384};  // fewer operations for the cut sweep

TEST(Stm32f405Slots, UpdateConfirmAndRevertOnTheRealSectorTable) {
  SlotTestDevice d(stm32f405_layout(), f405_identity());
  ASSERT_EQ(d.slots().layout_error(), UpdateError::kOk);
  ScriptedSelfTest test;
  EXPECT_EQ(d.slots().boot(test).source, ModelSource::kFactory);

  const Bytes first = image_for(f405_identity(), 1, 1);
  ASSERT_EQ(write_image(d.slots(), first, kDfuBlocks), UpdateError::kOk);
  EXPECT_EQ(d.slots().update_target(), SlotId::kA);
  EXPECT_EQ(d.slots().slot_region(SlotId::kA).offset, f405::kModelSlotAOffset);
  const FlashCounters& c = d.slots().update_counters();
  EXPECT_EQ(c.erases, 2u) << "sectors 8 and 9";
  EXPECT_EQ(c.programmed_bytes, 150000u + 256u);
  RecordProperty("f405_update_erases", static_cast<int>(c.erases));
  RecordProperty("f405_update_programmed_bytes", static_cast<int>(c.programmed_bytes));
  RecordProperty("f405_update_program_operations", static_cast<int>(c.program_operations));
  EXPECT_EQ(d.nor().erase_count(), 2u) << "sectors 10..11 and the firmware's 0..7 untouched";

  const BootChoice a = d.reboot_and_boot(true);
  EXPECT_EQ(a.source, ModelSource::kSlotA);
  EXPECT_EQ(a.payload.data(), d.nor().contents().data() + f405::kModelSlotAOffset + kSlotPayloadOffset)
      << "0x08080400 on the MCU";
  EXPECT_EQ(as_bytes(a.payload), as_bytes(payload_of(first)));
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).state, SlotState::kConfirmed);

  const Bytes second = image_for(f405_identity(), 2, 2);
  ASSERT_EQ(write_image(d.slots(), second, kDfuBlocks), UpdateError::kOk);
  EXPECT_EQ(d.slots().update_target(), SlotId::kB);
  EXPECT_EQ(d.slots().slot_region(SlotId::kB).offset, f405::kModelSlotBOffset);
  const BootChoice reverted = d.reboot_and_boot(false);
  EXPECT_EQ(reverted.source, ModelSource::kSlotA);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).last_error, UpdateError::kSelfTestFailed);
  EXPECT_EQ(d.nor().erase_count(), 4u);
}

TEST(Stm32f405Slots, ImageLargerThanA256KiBSlotIsRefused) {
  SlotTestDevice d(stm32f405_layout(), f405_identity());
  ScriptedSelfTest test;
  d.slots().boot(test);
  const Bytes huge = sign_image(header_for(f405_identity(), 1), random_bytes(f405::kModelSlotSize, 3), device_key());
  EXPECT_EQ(d.slots().begin_update(header_of(huge)), UpdateError::kImageTooLarge);
  EXPECT_EQ(d.nor().operation_count(), 0u);
}

TEST(Stm32f405Slots, PowerCutAtEveryOperationOfAnUpdate) {
  static const Bytes old_image = image_for(f405_identity(), 1, 1);
  static const Bytes new_image = image_for(f405_identity(), 2, 2);
  static const Bytes start = [] {
    SlotTestDevice d(stm32f405_layout(), f405_identity());
    ScriptedSelfTest pass;
    d.slots().boot(pass);
    if (write_image(d.slots(), old_image, kLargeChunks) != UpdateError::kOk) ADD_FAILURE() << "setup";
    d.reboot_and_boot(true);
    return d.cells();
  }();
  CutScenario s{stm32f405_layout(), f405_identity(), start, nullptr,
                {Bytes(old_image.begin() + kImageHeaderSize, old_image.end()),
                 Bytes(new_image.begin() + kImageHeaderSize, new_image.end())},
                true};
  s.script = [](SlotTestDevice& d) {
    d.reboot_and_boot(true);
    if (!d.nor().powered()) return;
    if (write_image(d.slots(), new_image, kLargeChunks) == UpdateError::kOk) d.reboot_and_boot(true);
  };
  const CutReport r = cut_at_every_operation(s);
  report_cuts("stm32f405_update", r);
  EXPECT_GE(r.cut_points, 10);
  EXPECT_EQ(r.unbootable, 0);
}

}  // namespace
}  // namespace hadynet::model_update::test
