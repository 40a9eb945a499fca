// The USB fuzzer's seeds (fuzz/usb_fuzz_seeds.h) through the fuzzer's
// harness and invariant checks, built with the regular compiler: each seed
// must run without an invariant violation (the harness aborts on one) and
// reach what it was written for (exact counts), so the fuzzer starts deep.
#include <gtest/gtest.h>
#include <sodium.h>

#include <memory>
#include <string>

#include "fuzz/usb_fuzz_harness.h"
#include "fuzz/usb_fuzz_model.h"
#include "fuzz/usb_fuzz_seeds.h"

namespace hadynet::usb::fuzz {
namespace {

namespace mu = model_update;

std::unique_ptr<UsbFuzzHarness> run(const std::vector<std::uint8_t>& input) {
  auto h = std::make_unique<UsbFuzzHarness>();
  h->run(input.data(), input.size());
  return h;
}

TEST(UsbFuzzSeeds, TheHarnessTrustsTheKeyTheSeedsSignWith) {
  ASSERT_GE(sodium_init(), 0);
  std::array<std::uint8_t, crypto_sign_SEEDBYTES> seed{};
  seed.fill(kFuzzKeySeedByte);
  mu::PublicKey pk{};
  std::array<std::uint8_t, crypto_sign_SECRETKEYBYTES> sk{};
  crypto_sign_seed_keypair(pk.data(), sk.data(), seed.data());
  EXPECT_EQ(pk, kFuzzPublicKey);
}

TEST(UsbFuzzSeeds, EnumerationConfiguresTheDevice) {
  const auto h = run(seeds::enumerate_and_read_descriptors());
  EXPECT_EQ(h->device().device().state(), DeviceState::kConfigured);
  EXPECT_EQ(h->device().device().address(), 9);
}

TEST(UsbFuzzSeeds, CdcTrafficIsEchoedAndTelemetrySent) {
  const auto h = run(seeds::cdc_traffic());
  EXPECT_EQ(h->device().cdc().line_coding().baud, 115200u);
  EXPECT_EQ(h->device().hid().sets_sent(), 1u);
  EXPECT_EQ(h->device().cdc().dropped_reply_bytes(), 0u);
}

TEST(UsbFuzzSeeds, DfuDownloadWritesAnImage) {
  const auto h = run(seeds::dfu_download(false));
  EXPECT_EQ(h->device().dfu_mode().images_written(), 1u);
  EXPECT_EQ(h->device().dfu_mode().state(), dfu::State::kIdle);
  EXPECT_EQ(h->slots().slot_status(mu::SlotId::kA).state, mu::SlotState::kValid);
}

TEST(UsbFuzzSeeds, DfuDownloadWithAPowerCutEndsInDfuError) {
  const auto h = run(seeds::dfu_download(true));
  EXPECT_EQ(h->device().dfu_mode().images_written(), 0u);
  EXPECT_FALSE(h->flash().powered());
}

TEST(UsbFuzzSeeds, AnImageOfAnotherKeyIsRefusedAtItsHeader) {
  const auto h = run(seeds::dfu_refused());
  EXPECT_EQ(h->device().dfu_mode().state(), dfu::State::kError);
  EXPECT_EQ(h->device().dfu_mode().status(), dfu::Status::kErrFile);
  EXPECT_EQ(h->device().dfu_mode().update_error(), mu::UpdateError::kSignedByOtherKey);
  EXPECT_EQ(std::string(h->device().dfu_mode().status_text()), "signed by another key");
  EXPECT_EQ(h->flash().erase_count(), 0u);
}

TEST(UsbFuzzSeeds, AnUpdateBootsAfterAResetAndTheNextOneGoesToTheOtherSlot) {
  const auto h = run(seeds::dfu_update_reset_update());
  EXPECT_EQ(h->slots().choice().source, mu::ModelSource::kSlotA);
  EXPECT_EQ(h->device().running().sequence, 1u);
  EXPECT_EQ(h->device().dfu_mode().images_written(), 1u);
  EXPECT_EQ(h->slots().slot_status(mu::SlotId::kB).state, mu::SlotState::kValid);
  EXPECT_EQ(h->slots().slot_status(mu::SlotId::kB).sequence, 2u);
}

}  // namespace
}  // namespace hadynet::usb::fuzz
