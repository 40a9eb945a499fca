// Images the update refuses, each with its specific error, and what a
// refusal leaves: begin_update() refusals touch no flash byte; later ones
// (append/finish) only leave the target slot without a header. The slot in
// use and the boot decision never change.
#include <gtest/gtest.h>

#include <algorithm>

#include "firmware/model_update/slot_layout.h"
#include "test/model_update/slot_test_device.h"

namespace hadynet::model_update::test {
namespace {

// The device every test starts from, booted: B (sequence 2) in use,
// updates target A.
struct Booted {
  SlotTestDevice device{small_layout(), small_identity(), two_confirmed_images()};
  BootChoice choice = device.reboot_and_boot(true);
};

bool header_erased(const SlotTestDevice& d, const flash::FlashRegion& slot) {
  return std::all_of(d.cells().begin() + slot.offset, d.cells().begin() + slot.offset + kImageHeaderSize,
                     [](std::uint8_t b) { return b == 0xFF; });
}

void expect_same_choice(const BootChoice& a, const BootChoice& b) {
  EXPECT_EQ(a.source, b.source);
  EXPECT_EQ(a.sequence, b.sequence);
  EXPECT_EQ(a.payload.data(), b.payload.data());
  EXPECT_EQ(a.payload.size(), b.payload.size());
}

// begin_update refuses `header` with `expected` and no flash byte changes.
void expect_refused_at_begin(Booted& b, std::span<const std::uint8_t> header, UpdateError expected) {
  const Bytes before = b.device.cells();
  const std::uint64_t ops = b.device.nor().operation_count();
  EXPECT_EQ(b.device.slots().begin_update(header), expected);
  EXPECT_EQ(b.device.slots().last_update_error(), expected);
  EXPECT_FALSE(b.device.slots().update_in_progress());
  EXPECT_EQ(b.device.nor().operation_count(), ops);
  EXPECT_TRUE(b.device.cells() == before) << "a refused header touches no flash byte";
  expect_same_choice(b.device.slots().choice(), b.choice);
}

// The image is refused after begin with `expected`: only the target (A)
// lost its header; B (in use) and everything else are byte-identical; the
// next boot chooses as before.
void expect_refused_later(Booted& b, UpdateError result, UpdateError expected, const Bytes& before) {
  EXPECT_EQ(result, expected);
  EXPECT_FALSE(b.device.slots().update_in_progress());
  EXPECT_EQ(b.device.slots().update_target(), SlotId::kA);
  EXPECT_TRUE(cells_without(b.device.cells(), small_layout().slot_a) == cells_without(before, small_layout().slot_a))
      << "nothing outside the target changed";
  EXPECT_TRUE(header_erased(b.device, small_layout().slot_a));
  EXPECT_EQ(b.device.slots().slot_status(SlotId::kA).state, SlotState::kEmpty);
  EXPECT_EQ(b.device.slots().slot_status(SlotId::kA).last_error, expected);
  expect_same_choice(b.device.slots().choice(), b.choice);
  EXPECT_EQ(b.device.slots().append_update(Bytes(1, 0)), UpdateError::kNoUpdateInProgress);
}

// What flipping `mask` in header byte `at` of a sequence-3 image must give.
UpdateError expected_for_header_flip(std::size_t at, std::uint8_t mask) {
  if (at < 8) return UpdateError::kMalformedHeader;  // magic, version, header size
  if (at < 10) return UpdateError::kContractMismatch;
  if (at == 10) return UpdateError::kNumericMismatch;
  if (at == 11) return mask == kFlagDowngradeAllowed ? UpdateError::kBadSignature : UpdateError::kMalformedHeader;
  if (at < 16) return UpdateError::kBadSignature;  // sequence 3 -> another non-zero number
  if (at < 24) return UpdateError::kShapeMismatch;
  if (at < 28) {
    const std::uint32_t length = 6000u ^ (static_cast<std::uint32_t>(mask) << (8 * (at - 24)));
    return length > 8192 - kSlotPayloadOffset ? UpdateError::kImageTooLarge : UpdateError::kPayloadLengthMismatch;
  }
  if (at < 60) return UpdateError::kBadSignature;     // self-test CRC, dims, used frac bits
  if (at < 64) return UpdateError::kMalformedHeader;  // unused frac bits
  if (at < 72) return UpdateError::kBadSignature;     // model hash
  if (at < 96) return UpdateError::kMalformedHeader;  // reserved
  if (at < 128) return UpdateError::kSignedByOtherKey;
  if (at < 160) return UpdateError::kBadSignature;    // payload hash
  if (at < 192) return UpdateError::kMalformedHeader;  // reserved
  return UpdateError::kBadSignature;                   // the signature itself
}

TEST(UpdateRejection, EveryHeaderByteWithAFlippedBit) {
  Booted b;
  const Bytes image = small_image(3, 30);
  int refused = 0;
  for (std::size_t at = 0; at < kImageHeaderSize; ++at) {
    for (const std::uint8_t mask : {static_cast<std::uint8_t>(1u << (at % 8)), static_cast<std::uint8_t>(0x01)}) {
      Bytes header(image.begin(), image.begin() + kImageHeaderSize);
      header[at] ^= mask;
      SCOPED_TRACE(testing::Message() << "byte " << at << " mask " << int{mask});
      expect_refused_at_begin(b, header, expected_for_header_flip(at, mask));
      ++refused;
    }
  }
  RecordProperty("header_flips_refused", refused);
  // The unflipped header is accepted (the test's image is good).
  EXPECT_EQ(b.device.slots().begin_update(header_of(image)), UpdateError::kOk);
}

TEST(UpdateRejection, PayloadBitFlipsAtAStrideFailAtFinish) {
  Booted b;
  const Bytes image = small_image(3, 30);
  int refused = 0;
  for (std::size_t at = 0; at < 6000; at += 97) {
    SCOPED_TRACE(testing::Message() << "payload byte " << at);
    const Bytes before = b.device.cells();
    Bytes bad = image;
    bad[kImageHeaderSize + at] ^= static_cast<std::uint8_t>(1u << (at % 8));
    expect_refused_later(b, write_image(b.device.slots(), bad), UpdateError::kPayloadHashMismatch, before);
    ++refused;
  }
  RecordProperty("payload_flips_refused", refused);
  expect_same_choice(b.device.reboot_and_boot(true), b.choice);
}

TEST(UpdateRejection, TruncatedImage) {
  Booted b;
  const Bytes before = b.device.cells();
  const Bytes image = small_image(3, 30);
  const Bytes truncated(image.begin(), image.end() - 10);
  expect_refused_later(b, write_image(b.device.slots(), truncated), UpdateError::kTruncated, before);
  expect_same_choice(b.device.reboot_and_boot(true), b.choice);
}

TEST(UpdateRejection, TooManyBytes) {
  Booted b;
  const Bytes before = b.device.cells();
  Bytes longer = small_image(3, 30);
  longer.push_back(0x5A);
  expect_refused_later(b, write_image(b.device.slots(), longer), UpdateError::kTooManyBytes, before);
  expect_same_choice(b.device.reboot_and_boot(true), b.choice);
}

TEST(UpdateRejection, TooManyBytesInTheFirstChunkTouchesNothing) {
  Booted b;
  Bytes longer = small_image(3, 30);
  longer.push_back(0x5A);
  const Bytes before = b.device.cells();
  ASSERT_EQ(b.device.slots().begin_update(header_of(longer)), UpdateError::kOk);
  EXPECT_EQ(b.device.slots().append_update(payload_of(longer)), UpdateError::kTooManyBytes);
  EXPECT_TRUE(b.device.cells() == before);
  EXPECT_EQ(b.device.slots().slot_status(SlotId::kA).state, SlotState::kConfirmed) << "target untouched";
}

TEST(UpdateRejection, WrongSignature) {
  Booted b;
  const Bytes image = small_image(3, 30);
  const Bytes other = small_image(4, 30);  // same payload, another header: a valid signature of other bytes
  Bytes header(image.begin(), image.begin() + kImageHeaderSize);
  std::copy(other.begin() + kSignedBytes, other.begin() + kImageHeaderSize, header.begin() + kSignedBytes);
  expect_refused_at_begin(b, header, UpdateError::kBadSignature);
  // Signed by another key while claiming the device's key.
  const Bytes forged = sign_image_claiming(header_for(small_identity(), 3), payload_of(image), other_key(),
                                           device_key().public_key);
  expect_refused_at_begin(b, header_of(forged), UpdateError::kBadSignature);
}

TEST(UpdateRejection, SignedByAnotherKey) {
  Booted b;
  const Bytes image = sign_image(header_for(small_identity(), 3), random_bytes(6000, 30), other_key());
  expect_refused_at_begin(b, header_of(image), UpdateError::kSignedByOtherKey);
}

TEST(UpdateRejection, ContractNumericShapeAndLengthMismatches) {
  Booted b;
  const Bytes payload = random_bytes(6000, 30);
  ModelImageHeader h = header_for(small_identity(), 3);
  h.contract_version = 4;
  expect_refused_at_begin(b, header_of(sign_image(h, payload, device_key())), UpdateError::kContractMismatch);
  h = header_for(small_identity(), 3);
  h.numeric = kNumericF32;
  expect_refused_at_begin(b, header_of(sign_image(h, payload, device_key())), UpdateError::kNumericMismatch);
  h = header_for(small_identity(), 3);
  h.shape_id ^= 0x8000000000000000ull;
  expect_refused_at_begin(b, header_of(sign_image(h, payload, device_key())), UpdateError::kShapeMismatch);
  h = header_for(small_identity(), 3);
  expect_refused_at_begin(b, header_of(sign_image(h, random_bytes(5996, 30), device_key())),
                          UpdateError::kPayloadLengthMismatch);
}

TEST(UpdateRejection, ImageLargerThanASlot) {
  Booted b;
  const ModelImageHeader h = header_for(small_identity(), 3);
  expect_refused_at_begin(b, header_of(sign_image(h, random_bytes(8192 - 1024 + 4, 30), device_key())),
                          UpdateError::kImageTooLarge);
}

TEST(UpdateRejection, OlderOrEqualSequence) {
  Booted b;
  expect_refused_at_begin(b, header_of(small_image(2, 99)), UpdateError::kNotNewer);
  expect_refused_at_begin(b, header_of(small_image(1, 99)), UpdateError::kNotNewer);
}

TEST(UpdateRejection, MalformedAndOutOfOrderCalls) {
  SlotTestDevice fresh(small_layout(), small_identity());
  EXPECT_EQ(fresh.slots().begin_update(header_of(small_image(1, 1))), UpdateError::kNotBooted);
  Booted b;
  const Bytes image = small_image(3, 30);
  expect_refused_at_begin(b, std::span<const std::uint8_t>(image).first(255), UpdateError::kMalformedHeader);
  expect_refused_at_begin(b, std::span<const std::uint8_t>(image).first(257), UpdateError::kMalformedHeader);
  Bytes erased(kImageHeaderSize, 0xFF);
  expect_refused_at_begin(b, erased, UpdateError::kMalformedHeader);
  EXPECT_EQ(b.device.slots().append_update(payload_of(image)), UpdateError::kNoUpdateInProgress);
  EXPECT_EQ(b.device.slots().finish_update(), UpdateError::kNoUpdateInProgress);
}

TEST(UpdateRejection, FlashWriteErrorLeavesOnlyTheTargetWithoutHeader) {
  Booted b;
  const Bytes before = b.device.cells();
  b.device.nor().fail_write_at(b.device.nor().operation_count() + 5);
  const UpdateError e = write_image(b.device.slots(), small_image(3, 30));
  expect_refused_later(b, e, UpdateError::kFlashError, before);
  EXPECT_EQ(b.device.slots().last_flash_status(), flash::FlashStatus::kWriteError);
  expect_same_choice(b.device.reboot_and_boot(true), b.choice);
}

}  // namespace
}  // namespace hadynet::model_update::test
