// Accepted updates (firmware/model_update/model_slots.h): the target slot,
// any chunking, the counters, the forced downgrade and its documented
// effect, aborts.
#include <gtest/gtest.h>

#include <algorithm>

#include "firmware/model_update/slot_layout.h"
#include "test/model_update/slot_test_device.h"

namespace hadynet::model_update::test {
namespace {

Bytes as_bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }

TEST(Update, WritesTheSlotNotInUseAndTheNextBootTriesIt) {
  SlotTestDevice d(small_layout(), small_identity());
  install(d, small_image(1, 10));
  install(d, small_image(2, 20));
  ASSERT_EQ(d.slots().choice().source, ModelSource::kSlotB);
  const Bytes in_use = d.slot_bytes(SlotId::kB);
  const Bytes image = small_image(3, 30);
  ASSERT_EQ(write_image(d.slots(), image), UpdateError::kOk);
  EXPECT_EQ(d.slots().update_target(), SlotId::kA);
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).state, SlotState::kValid);
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).sequence, 3u);
  EXPECT_EQ(d.slot_bytes(SlotId::kB), in_use);
  EXPECT_EQ(d.slots().choice().source, ModelSource::kSlotB) << "the running model does not change";
  const Bytes a = d.slot_bytes(SlotId::kA);
  EXPECT_EQ(Bytes(a.begin(), a.begin() + kImageHeaderSize), as_bytes(header_of(image)));
  EXPECT_EQ(Bytes(a.begin() + kSlotPayloadOffset, a.begin() + kSlotPayloadOffset + 6000), as_bytes(payload_of(image)));
  const BootChoice c = d.reboot_and_boot(true);
  EXPECT_EQ(c.source, ModelSource::kSlotA);
  EXPECT_TRUE(c.trial_this_boot);
  EXPECT_EQ(as_bytes(c.payload), as_bytes(payload_of(image)));
}

TEST(Update, WithTheFactoryModelInUseTheEmptyOrOlderSlotIsTheTarget) {
  SlotTestDevice d(small_layout(), small_identity());
  ScriptedSelfTest test;
  d.slots().boot(test);
  ASSERT_EQ(write_image(d.slots(), small_image(1, 10)), UpdateError::kOk);
  EXPECT_EQ(d.slots().update_target(), SlotId::kA);
  ASSERT_EQ(write_image(d.slots(), small_image(2, 20)), UpdateError::kOk);
  EXPECT_EQ(d.slots().update_target(), SlotId::kB) << "A holds a valid image, B is empty";
  ASSERT_EQ(write_image(d.slots(), small_image(3, 30)), UpdateError::kOk);
  EXPECT_EQ(d.slots().update_target(), SlotId::kA) << "both valid: the lower sequence";
  EXPECT_EQ(d.reboot_and_boot(true).sequence, 3u);
}

TEST(Update, ReplacesAnInvalidSlotWhileTheFactoryModelRuns) {
  SlotTestDevice d(small_layout(), small_identity());
  ASSERT_EQ(install(d, small_image(1, 10), false).source, ModelSource::kFactory);
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).state, SlotState::kInvalid);
  ASSERT_EQ(write_image(d.slots(), small_image(1, 11)), UpdateError::kOk)
      << "an invalid slot's sequence does not count for the downgrade rule";
  EXPECT_EQ(d.slots().update_target(), SlotId::kA) << "both hold nothing usable: A";
  EXPECT_EQ(d.reboot_and_boot(true).source, ModelSource::kSlotA);
}

TEST(Update, AnyChunkingWritesTheSameBytes) {
  const Bytes image = small_image(1, 10);
  Bytes reference;
  for (const std::size_t chunk : {std::size_t{6000}, std::size_t{1}, std::size_t{3}, std::size_t{4096}}) {
    SlotTestDevice d(small_layout(), small_identity());
    ScriptedSelfTest test;
    d.slots().boot(test);
    const std::size_t chunks[] = {chunk};
    ASSERT_EQ(write_image(d.slots(), image, chunks), UpdateError::kOk) << chunk;
    if (reference.empty()) reference = d.slot_bytes(SlotId::kA);
    EXPECT_EQ(d.slot_bytes(SlotId::kA), reference) << chunk;
  }
}

TEST(Update, CountsErasesAndProgrammedBytes) {
  SlotTestDevice d(small_layout(), small_identity());
  ScriptedSelfTest test;
  d.slots().boot(test);
  const std::size_t whole[] = {6000};
  ASSERT_EQ(write_image(d.slots(), small_image(1, 10), whole), UpdateError::kOk);
  const FlashCounters& c = d.slots().update_counters();
  EXPECT_EQ(c.erases, 2u) << "the slot's two 4 KiB sectors";
  EXPECT_EQ(c.programmed_bytes, 6000u + 256u) << "payload and header";
  EXPECT_EQ(c.program_operations, 3u) << "payload split at the sector boundary, then the header";
  RecordProperty("update_erases", static_cast<int>(c.erases));
  RecordProperty("update_programmed_bytes", static_cast<int>(c.programmed_bytes));
}

TEST(Update, ForcedDowngradeWinsAndItsFallbackIsTheFactoryModel) {
  SlotTestDevice d(small_layout(), small_identity(), two_confirmed_images());
  d.reboot_and_boot(true);
  ModelImageHeader h = header_for(small_identity(), 1);
  h.downgrade_allowed = true;
  const Bytes payload = random_bytes(6000, 111);
  const Bytes downgrade = sign_image(h, payload, device_key());
  ASSERT_EQ(write_image(d.slots(), downgrade), UpdateError::kOk);
  EXPECT_EQ(d.slots().update_target(), SlotId::kA);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).state, SlotState::kInvalid) << "the newer image gives way";
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).last_error, UpdateError::kMarkedInvalid);
  EXPECT_EQ(d.slots().update_counters().programmed_bytes, 6000u + 256u + 4u) << "payload, header, B's invalid flag";
  EXPECT_EQ(d.slots().choice().source, ModelSource::kSlotB) << "B keeps running until the reset";
  const Bytes after_update = d.cells();

  const BootChoice c = d.reboot_and_boot(true);
  EXPECT_EQ(c.source, ModelSource::kSlotA);
  EXPECT_EQ(c.sequence, 1u);
  EXPECT_EQ(as_bytes(c.payload), payload);

  // The documented effect: the old image is gone for good, so a failing
  // trial of the downgrade falls back to the factory model.
  SlotTestDevice failing(small_layout(), small_identity(), after_update);
  EXPECT_EQ(failing.reboot_and_boot(false).source, ModelSource::kFactory);
}

TEST(Update, ForcedDowngradeToTheSameSequence) {
  SlotTestDevice d(small_layout(), small_identity(), two_confirmed_images());
  d.reboot_and_boot(true);
  ModelImageHeader h = header_for(small_identity(), 2);
  h.downgrade_allowed = true;
  const Bytes payload = random_bytes(6000, 222);
  ASSERT_EQ(write_image(d.slots(), sign_image(h, payload, device_key())), UpdateError::kOk);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).state, SlotState::kInvalid);
  EXPECT_EQ(as_bytes(d.reboot_and_boot(true).payload), payload);
}

TEST(Update, DowngradeFlagOnANewerImageKeepsTheFallback) {
  SlotTestDevice d(small_layout(), small_identity(), two_confirmed_images());
  d.reboot_and_boot(true);
  ModelImageHeader h = header_for(small_identity(), 3);
  h.downgrade_allowed = true;
  ASSERT_EQ(write_image(d.slots(), sign_image(h, random_bytes(6000, 33), device_key())), UpdateError::kOk);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).state, SlotState::kConfirmed);
  EXPECT_EQ(d.reboot_and_boot(false).source, ModelSource::kSlotB) << "a failing trial reverts to B";
}

TEST(Update, AbortLeavesOnlyTheTargetWithoutHeader) {
  SlotTestDevice d(small_layout(), small_identity(), two_confirmed_images());
  d.reboot_and_boot(true);
  const Bytes before = d.cells();
  const Bytes image = small_image(3, 30);
  ASSERT_EQ(d.slots().begin_update(header_of(image)), UpdateError::kOk);
  ASSERT_EQ(d.slots().append_update(payload_of(image).first(3000)), UpdateError::kOk);
  EXPECT_EQ(d.slots().update_received(), 3000u);
  d.slots().abort_update();
  EXPECT_FALSE(d.slots().update_in_progress());
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).state, SlotState::kEmpty);
  EXPECT_TRUE(cells_without(d.cells(), d.region(SlotId::kA)) == cells_without(before, d.region(SlotId::kA)));
  EXPECT_EQ(d.reboot_and_boot(true).source, ModelSource::kSlotB);
}

TEST(Update, BeginRestartsAnUnfinishedUpdateAndBootEndsOne) {
  SlotTestDevice d(small_layout(), small_identity(), two_confirmed_images());
  d.reboot_and_boot(true);
  const Bytes first = small_image(3, 30);
  ASSERT_EQ(d.slots().begin_update(header_of(first)), UpdateError::kOk);
  ASSERT_EQ(d.slots().append_update(payload_of(first).first(4000)), UpdateError::kOk);
  const Bytes second = small_image(4, 40);
  ASSERT_EQ(write_image(d.slots(), second), UpdateError::kOk);
  EXPECT_EQ(d.slots().update_target(), SlotId::kA);

  const Bytes third = small_image(5, 50);
  ASSERT_EQ(d.slots().begin_update(header_of(third)), UpdateError::kOk);
  ASSERT_EQ(d.slots().append_update(payload_of(third).first(100)), UpdateError::kOk);
  ScriptedSelfTest test;
  d.slots().boot(test);  // e.g. a reset without power loss
  EXPECT_FALSE(d.slots().update_in_progress());
  EXPECT_EQ(d.slots().finish_update(), UpdateError::kNoUpdateInProgress);
  EXPECT_EQ(d.slots().choice().source, ModelSource::kSlotB);
}

}  // namespace
}  // namespace hadynet::model_update::test
