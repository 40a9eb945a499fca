// The USB fuzzer's seeds (fuzz/usb_fuzz_seeds.h) through the fuzzer's
// harness and invariant checks, built with the regular compiler: each seed
// must run without an invariant violation (the harness aborts on one) and
// reach what it was written for (exact counts), so the fuzzer starts deep.
#include <gtest/gtest.h>

#include <memory>

#include "fuzz/usb_fuzz_harness.h"
#include "fuzz/usb_fuzz_seeds.h"

namespace hadynet::usb::fuzz {
namespace {

std::unique_ptr<UsbFuzzHarness> run(const std::vector<std::uint8_t>& input) {
  auto h = std::make_unique<UsbFuzzHarness>();
  h->run(input.data(), input.size());
  return h;
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
}

TEST(UsbFuzzSeeds, DfuDownloadWithAPowerCutEndsInDfuError) {
  const auto h = run(seeds::dfu_download(true));
  EXPECT_EQ(h->device().dfu_mode().images_written(), 0u);
  EXPECT_FALSE(h->flash().powered());
}

}  // namespace
}  // namespace hadynet::usb::fuzz
