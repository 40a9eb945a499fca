// The boot rule (firmware/model_update/model_slots.h): highest valid
// sequence wins, a new image is marked tried before its self-test, pass
// confirms, failure or an interrupted trial reverts (to the other slot or
// the factory model); slots failing a check are skipped.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "firmware/model_update/slot_layout.h"
#include "test/model_update/slot_test_device.h"

namespace hadynet::model_update::test {
namespace {

std::uint32_t flag_word(const SlotTestDevice& d, const flash::FlashRegion& slot, TrialFlag flag) {
  const std::size_t at = slot.offset + trial_flag_offset(flag);
  return static_cast<std::uint32_t>(d.cells()[at]) | (static_cast<std::uint32_t>(d.cells()[at + 1]) << 8) |
         (static_cast<std::uint32_t>(d.cells()[at + 2]) << 16) | (static_cast<std::uint32_t>(d.cells()[at + 3]) << 24);
}

Bytes as_bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }

TEST(BootRule, EmptySlotsBootTheFactoryModelWithoutWriting) {
  SlotTestDevice d(small_layout(), small_identity());
  ScriptedSelfTest test;
  const BootChoice c = d.slots().boot(test);
  EXPECT_EQ(c.source, ModelSource::kFactory);
  EXPECT_EQ(c.sequence, 0u);
  EXPECT_TRUE(c.payload.empty());
  EXPECT_EQ(test.calls, 0);
  EXPECT_EQ(d.nor().operation_count(), 0u);
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).state, SlotState::kEmpty);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).state, SlotState::kEmpty);
}

TEST(BootRule, NewImageIsMarkedTriedBeforeItsSelfTestThenConfirmed) {
  SlotTestDevice d(small_layout(), small_identity());
  const Bytes image = small_image(1, 10);
  ScriptedSelfTest first;
  d.slots().boot(first);
  ASSERT_EQ(write_image(d.slots(), image), UpdateError::kOk);
  EXPECT_EQ(d.slots().update_target(), SlotId::kA) << "factory in use, both empty: A";
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).state, SlotState::kValid);

  const flash::FlashRegion a = small_layout().slot_a;
  ScriptedSelfTest test;
  std::uint32_t tried_during_test = 0;
  std::uint32_t confirmed_during_test = 0;
  test.during_run = [&] {
    tried_during_test = flag_word(d, a, TrialFlag::kTried);
    confirmed_during_test = flag_word(d, a, TrialFlag::kConfirmed);
  };
  const BootChoice c = d.reboot_and_boot(test);
  EXPECT_EQ(tried_during_test, trial_flag_magic(TrialFlag::kTried)) << "tried is on the flash before the trial";
  EXPECT_EQ(confirmed_during_test, kErasedWord);
  EXPECT_EQ(flag_word(d, a, TrialFlag::kConfirmed), trial_flag_magic(TrialFlag::kConfirmed));
  EXPECT_EQ(flag_word(d, a, TrialFlag::kInvalid), kErasedWord);
  EXPECT_EQ(test.calls, 1);
  EXPECT_EQ(test.last_payload, as_bytes(payload_of(image)));
  EXPECT_EQ(test.last_self_test_checksum, 0xC0FFEE00u + 1);
  EXPECT_EQ(c.source, ModelSource::kSlotA);
  EXPECT_EQ(c.sequence, 1u);
  EXPECT_TRUE(c.trial_this_boot);
  EXPECT_EQ(c.payload.data(), d.nor().contents().data() + a.offset + kSlotPayloadOffset) << "in place (XIP)";
  EXPECT_EQ(as_bytes(c.payload), as_bytes(payload_of(image)));
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).state, SlotState::kConfirmed);
}

TEST(BootRule, ConfirmedImageBootsWithoutSelfTestOrWrites) {
  SlotTestDevice d(small_layout(), small_identity());
  install(d, small_image(1, 10));
  const std::uint64_t ops = d.nor().operation_count();
  ScriptedSelfTest test;
  const BootChoice c = d.reboot_and_boot(test);
  EXPECT_EQ(c.source, ModelSource::kSlotA);
  EXPECT_FALSE(c.trial_this_boot);
  EXPECT_EQ(test.calls, 0);
  EXPECT_EQ(d.nor().operation_count(), ops);
}

TEST(BootRule, HighestSequenceWins) {
  SlotTestDevice d(small_layout(), small_identity());
  install(d, small_image(1, 10));
  const BootChoice b = install(d, small_image(2, 20));
  EXPECT_EQ(b.source, ModelSource::kSlotB);
  EXPECT_EQ(b.sequence, 2u);
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).state, SlotState::kConfirmed) << "the old image stays as fallback";
  const BootChoice again = install(d, small_image(3, 30));
  EXPECT_EQ(again.source, ModelSource::kSlotA) << "the slot not in use (A) took image 3";
  EXPECT_EQ(again.sequence, 3u);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).state, SlotState::kConfirmed);
}

TEST(BootRule, SelfTestFailureRevertsToTheOtherSlot) {
  SlotTestDevice d(small_layout(), small_identity());
  const Bytes old_image = small_image(1, 10);
  install(d, old_image);
  ScriptedSelfTest failing(false);
  ASSERT_EQ(write_image(d.slots(), small_image(2, 20)), UpdateError::kOk);
  const BootChoice c = d.reboot_and_boot(failing);
  EXPECT_EQ(failing.calls, 1);
  EXPECT_EQ(c.source, ModelSource::kSlotA);
  EXPECT_EQ(as_bytes(c.payload), as_bytes(payload_of(old_image)));
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).state, SlotState::kInvalid);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).last_error, UpdateError::kSelfTestFailed);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).sequence, 2u);
  // For good: the next boot skips B without testing it.
  ScriptedSelfTest next;
  EXPECT_EQ(d.reboot_and_boot(next).source, ModelSource::kSlotA);
  EXPECT_EQ(next.calls, 0);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).last_error, UpdateError::kMarkedInvalid);
}

TEST(BootRule, SelfTestFailureRevertsToTheFactoryModel) {
  SlotTestDevice d(small_layout(), small_identity());
  const BootChoice c = install(d, small_image(1, 10), /*self_test_passes=*/false);
  EXPECT_EQ(c.source, ModelSource::kFactory);
  EXPECT_TRUE(c.payload.empty());
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).state, SlotState::kInvalid);
}

TEST(BootRule, TrialInterruptedAfterTriedIsInvalidatedOnTheNextBoot) {
  SlotTestDevice d(small_layout(), small_identity());
  const Bytes old_image = small_image(1, 10);
  install(d, old_image);
  ASSERT_EQ(write_image(d.slots(), small_image(2, 20)), UpdateError::kOk);
  // The device dies inside the trial: the flash as it is during the self-test.
  Bytes during_trial;
  ScriptedSelfTest crashing;
  crashing.during_run = [&] { during_trial = d.cells(); };
  d.reboot_and_boot(crashing);
  ASSERT_FALSE(during_trial.empty());

  SlotTestDevice after(small_layout(), small_identity(), during_trial);
  ScriptedSelfTest test;
  const BootChoice c = after.reboot_and_boot(test);
  EXPECT_EQ(c.source, ModelSource::kSlotA);
  EXPECT_EQ(as_bytes(c.payload), as_bytes(payload_of(old_image)));
  EXPECT_EQ(test.calls, 0) << "the interrupted image is not tried twice";
  EXPECT_EQ(after.slots().slot_status(SlotId::kB).state, SlotState::kInvalid);
  EXPECT_EQ(after.slots().slot_status(SlotId::kB).last_error, UpdateError::kTrialNotConfirmed);
  EXPECT_EQ(flag_word(after, small_layout().slot_b, TrialFlag::kInvalid), trial_flag_magic(TrialFlag::kInvalid));
}

TEST(BootRule, AConfirmedWordOtherThanItsMagicDoesNotConfirm) {
  SlotTestDevice d(small_layout(), small_identity());
  install(d, small_image(1, 10));
  ASSERT_EQ(write_image(d.slots(), small_image(2, 20)), UpdateError::kOk);
  // Tried, and a torn "confirmed" (half its bytes programmed).
  const flash::FlashRegion b = small_layout().slot_b;
  ASSERT_EQ(d.nor().program(b.offset + trial_flag_offset(TrialFlag::kTried), Bytes{0x54, 0x52, 0x59, 0x44}),
            flash::FlashStatus::kOk);
  ASSERT_EQ(d.nor().program(b.offset + trial_flag_offset(TrialFlag::kConfirmed), Bytes{0x43, 0x4F, 0xFF, 0xFF}),
            flash::FlashStatus::kOk);
  const BootChoice c = d.reboot_and_boot(true);
  EXPECT_EQ(c.source, ModelSource::kSlotA);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).last_error, UpdateError::kTrialNotConfirmed);
}

TEST(BootRule, ATornTriedFlagCountsAsTried) {
  SlotTestDevice d(small_layout(), small_identity());
  install(d, small_image(1, 10));
  ASSERT_EQ(write_image(d.slots(), small_image(2, 20)), UpdateError::kOk);
  const flash::FlashRegion b = small_layout().slot_b;
  ASSERT_EQ(d.nor().program(b.offset + trial_flag_offset(TrialFlag::kTried), Bytes{0x54, 0x52, 0xFF, 0xFF}),
            flash::FlashStatus::kOk);
  ScriptedSelfTest test;
  EXPECT_EQ(d.reboot_and_boot(test).source, ModelSource::kSlotA);
  EXPECT_EQ(test.calls, 0);
}

TEST(BootRule, SlotsCorruptedInFlashAreSkipped) {
  SlotTestDevice d(small_layout(), small_identity());
  install(d, small_image(1, 10));
  install(d, small_image(2, 20));
  const flash::FlashRegion b = small_layout().slot_b;
  Bytes& cells = d.raw_cells();
  cells[b.offset + kSlotPayloadOffset + 4321] ^= 0x10;  // bit rot in B's payload
  EXPECT_EQ(d.reboot_and_boot(true).source, ModelSource::kSlotA);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).state, SlotState::kInvalid);
  EXPECT_EQ(d.slots().slot_status(SlotId::kB).last_error, UpdateError::kPayloadHashMismatch);
  const flash::FlashRegion a = small_layout().slot_a;
  cells[a.offset + 40] ^= 0x01;  // header byte 40: a dim (signed information)
  EXPECT_EQ(d.reboot_and_boot(true).source, ModelSource::kFactory);
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).last_error, UpdateError::kBadSignature);
}

TEST(BootRule, ImagesForAnotherFirmwareAreSkipped) {
  SlotTestDevice d(small_layout(), small_identity());
  install(d, small_image(1, 10));
  ModelIdentity other = small_identity();
  other.shape_id ^= 1;
  SlotTestDevice same_flash_other_model(small_layout(), other, d.cells());
  EXPECT_EQ(same_flash_other_model.reboot_and_boot(true).source, ModelSource::kFactory);
  EXPECT_EQ(same_flash_other_model.slots().slot_status(SlotId::kA).last_error, UpdateError::kShapeMismatch);
}

TEST(BootRule, AnotherDevicesKeyIsNotTrusted) {
  SlotTestDevice d(small_layout(), small_identity());
  // Written directly: begin_update would refuse it.
  const Bytes foreign = sign_image(header_for(small_identity(), 5), random_bytes(6000, 5), other_key());
  const flash::FlashRegion a = small_layout().slot_a;
  Bytes& cells = d.raw_cells();
  std::copy(foreign.begin(), foreign.begin() + kImageHeaderSize, cells.begin() + a.offset);
  std::copy(foreign.begin() + kImageHeaderSize, foreign.end(), cells.begin() + a.offset + kSlotPayloadOffset);
  EXPECT_EQ(d.reboot_and_boot(true).source, ModelSource::kFactory);
  EXPECT_EQ(d.slots().slot_status(SlotId::kA).last_error, UpdateError::kSignedByOtherKey);
}

TEST(BootRule, BadSlotLayoutBootsTheFactoryModelAndRefusesUpdates) {
  SlotTestDevice d(small_layout(), small_identity());
  ModelSlots overlapping(d.nor(), small_layout().slot_a, {3 * 4096, 2 * 4096}, small_identity(),
                         std::span<const std::uint8_t, kPublicKeyBytes>(device_key().public_key), d.nor().contents());
  EXPECT_EQ(overlapping.layout_error(), UpdateError::kBadSlotLayout);
  ScriptedSelfTest test;
  EXPECT_EQ(overlapping.boot(test).source, ModelSource::kFactory);
  EXPECT_EQ(overlapping.begin_update(header_of(small_image(1, 1))), UpdateError::kBadSlotLayout);
  ModelSlots unmapped(d.nor(), small_layout().slot_a, small_layout().slot_b, small_identity(),
                      std::span<const std::uint8_t, kPublicKeyBytes>(device_key().public_key),
                      d.nor().contents().first(4096));
  EXPECT_EQ(unmapped.layout_error(), UpdateError::kBadSlotLayout);
  ModelIdentity too_big = small_identity();
  too_big.payload_length = 8192 - 1024 + 1;
  ModelSlots small(d.nor(), small_layout().slot_a, small_layout().slot_b, too_big,
                   std::span<const std::uint8_t, kPublicKeyBytes>(device_key().public_key), d.nor().contents());
  EXPECT_EQ(small.layout_error(), UpdateError::kBadSlotLayout);
}

TEST(BootRule, EveryErrorAndStateHasItsOwnText) {
  std::set<std::string> texts;
  for (int e = 0; e <= static_cast<int>(UpdateError::kBadSlotLayout); ++e) {
    texts.insert(update_error_text(static_cast<UpdateError>(e)));
  }
  EXPECT_EQ(texts.size(), static_cast<std::size_t>(UpdateError::kBadSlotLayout) + 1);
  EXPECT_STREQ(slot_state_text(SlotState::kTried), "tried");
  EXPECT_STREQ(model_source_text(ModelSource::kSlotB), "slot B");
}

}  // namespace
}  // namespace hadynet::model_update::test
