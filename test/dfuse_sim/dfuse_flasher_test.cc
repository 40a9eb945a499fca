// The host flasher (tools/usb/firmware_flasher.h) against the simulated ROM
// bootloader in-process: DfuClient over SimDfuTransport (whole control
// transfers on the sim's FakeController), a fake sleep, the memory layout
// parsed from the string the sim's alternate 0 names. Success, and each
// failure with its exit code. Bytes compare exactly; times are simulated.
#include <gtest/gtest.h>

#include <string>

#include "test/dfuse_sim/sim_host.h"
#include "tools/usb/dfuse_memory_layout.h"
#include "tools/usb/firmware_flasher.h"

namespace hadynet::usb::host_testing {
namespace {

using tools::usb::DfuClient;
using tools::usb::DfuseMemoryLayout;
using tools::usb::FirmwareFlasher;
using tools::usb::FirmwareImage;
using tools::usb::FlashError;
using tools::usb::FlashPhase;
using tools::usb::FlashProgress;

constexpr std::uint32_t kFlash = 0x08000000;
constexpr std::size_t kImageSize = 150 * 1024 + 100;  // sectors 0..3 (16K), 4 (64K), 5 (128K); a short last block
constexpr std::uint8_t kPattern = 0xA5;               // what the sectors the image does not cover hold

class FlasherAgainstSimTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(enumerate(sim.controller()));
    // The layout as a host reads it: alternate 0's iInterface string.
    const Bytes config = control_in(sim.controller(), get_descriptor(descriptor::kConfiguration, 0, 255));
    ASSERT_GE(config.size(), 18u);
    const std::string text = read_string(sim.controller(), config[9 + 8]);
    std::string error;
    const auto parsed = tools::usb::parse_dfuse_memory_layout(text, error);
    ASSERT_TRUE(parsed.has_value()) << error;
    layout = *parsed;
    // Every sector from 6 on holds the pattern; it must survive.
    sim.flash().fill(0x08040000, Bytes(0xC0000, kPattern));
    image.address = kFlash;
    image.bytes = pseudo_random(kImageSize, 42);
  }

  // Runs flash(); the FlashError's exit code, or 0 on success.
  int flash() {
    DfuClient client(transport, sleep.function());
    FirmwareFlasher flasher(client, layout, kDfuseTransferSize,
                            [this](const FlashProgress& p) { progress.push_back(p); });
    try {
      flasher.flash(image);
      return 0;
    } catch (const FlashError& e) {
      message = e.what();
      return e.exit_code();
    }
  }

  Bytes flash_bytes(std::uint32_t address, std::size_t n) {
    const auto cells = sim.flash().cells();
    return Bytes(cells.begin() + (address - kFlash), cells.begin() + (address - kFlash) + n);
  }

  // Per phase: totals constant, `done` never decreasing, never past the total.
  void expect_monotone_progress() {
    for (std::size_t i = 1; i < progress.size(); ++i) {
      const FlashProgress& a = progress[i - 1];
      const FlashProgress& b = progress[i];
      EXPECT_LE(b.done, b.total);
      if (a.phase == b.phase) {
        EXPECT_EQ(a.total, b.total);
        EXPECT_GE(b.done, a.done) << "progress went back in phase " << tools::usb::phase_name(b.phase);
      }
    }
  }

  Stm32RomBootloader sim;
  SimDfuTransport transport{sim};
  FakeSleep sleep;
  DfuseMemoryLayout layout;
  FirmwareImage image;
  std::vector<FlashProgress> progress;
  std::string message;
};

TEST_F(FlasherAgainstSimTest, FlashesVerifiesAndLeaves) {
  ASSERT_EQ(flash(), 0) << message;
  EXPECT_EQ(flash_bytes(kFlash, kImageSize), image.bytes);
  // Sector 5 (0x08020000, 128 KiB) is covered in part: the rest reads erased.
  EXPECT_EQ(flash_bytes(kFlash + kImageSize, 0x40000 - kImageSize), Bytes(0x40000 - kImageSize, 0xFF));
  EXPECT_EQ(flash_bytes(0x08040000, 0xC0000), Bytes(0xC0000, kPattern)) << "sectors 6..11 untouched";
  for (std::size_t s = 0; s < 12; ++s) EXPECT_EQ(sim.flash().erases_of(s), s <= 5 ? 1u : 0u) << "sector " << s;
  EXPECT_FALSE(sim.attached());
  ASSERT_TRUE(sim.jump_address().has_value());
  EXPECT_EQ(*sim.jump_address(), kFlash);

  // Simulated waits, exact (fake clock): erases 4 x 800 + 2400 + 4000 ms
  // (datasheet worst cases); 75 full blocks x 52 ms (2048 B x 25 us, rounded
  // up) + the 100-byte block 3 ms; three set-address commands 1 ms each.
  EXPECT_EQ(sleep.total_ms, 4u * 800 + 2400 + 4000 + 75u * 52 + 3 + 3 * 1);

  expect_monotone_progress();
  const std::uint64_t erase_total = 4 * 16384 + 65536 + 131072;
  ASSERT_FALSE(progress.empty());
  std::uint64_t last_done[3] = {}, last_total[3] = {};
  for (const FlashProgress& p : progress) {
    last_done[static_cast<int>(p.phase)] = p.done;
    last_total[static_cast<int>(p.phase)] = p.total;
  }
  EXPECT_EQ(last_total[static_cast<int>(FlashPhase::kErase)], erase_total);
  EXPECT_EQ(last_done[static_cast<int>(FlashPhase::kErase)], erase_total);
  for (FlashPhase p : {FlashPhase::kWrite, FlashPhase::kVerify}) {
    EXPECT_EQ(last_total[static_cast<int>(p)], kImageSize);
    EXPECT_EQ(last_done[static_cast<int>(p)], kImageSize);
  }
}

TEST_F(FlasherAgainstSimTest, ImageTooLargeTouchesNothing) {
  image.bytes = pseudo_random(1024 * 1024 + 1, 1);  // one byte more than the 1 MiB flash
  EXPECT_EQ(flash(), 3) << message;
  EXPECT_NE(message.find("does not fit"), std::string::npos) << message;
  EXPECT_EQ(sim.dfu().downloads(), 0u);
  EXPECT_EQ(sim.flash().erase_count(), 0u);
  EXPECT_EQ(transport.requests(), 0u) << "refused before any request";
  EXPECT_TRUE(sim.attached());
}

TEST_F(FlasherAgainstSimTest, ImageOutsideFlashTouchesNothing) {
  image.address = 0x07FFF000;  // 4 KiB below the flash
  EXPECT_EQ(flash(), 3) << message;
  EXPECT_NE(message.find("starts outside"), std::string::npos) << message;
  EXPECT_EQ(sim.flash().erase_count(), 0u);
  EXPECT_EQ(transport.requests(), 0u);
}

TEST_F(FlasherAgainstSimTest, DeviceVanishingMidWayIsExitCode4) {
  {
    DfuseFaults f;
    f.vanish_after_block = 12;
    sim.set_faults(f);
  }
  EXPECT_EQ(flash(), 4) << message;
  EXPECT_NE(message.find("vanished"), std::string::npos) << message;
  EXPECT_FALSE(sim.attached());
  EXPECT_FALSE(sim.jump_address().has_value());
  // Blocks 2..12 (11 x 2048 bytes) reached the flash before it went.
  EXPECT_EQ(flash_bytes(kFlash, 11 * 2048), Bytes(image.bytes.begin(), image.bytes.begin() + 11 * 2048));
}

TEST_F(FlasherAgainstSimTest, StatusErrorMidWayIsExitCode5) {
  {
    DfuseFaults f;
    f.error_at_block = 20;
    f.error_status = dfu::Status::kErrProg;
    sim.set_faults(f);
  }
  EXPECT_EQ(flash(), 5) << message;
  EXPECT_NE(message.find("errPROG"), std::string::npos) << message;
  EXPECT_NE(message.find("dfuERROR"), std::string::npos) << message;
  EXPECT_TRUE(sim.attached()) << "the device stays in the bootloader";
  EXPECT_EQ(sim.dfu().state(), dfu::State::kError);
}

TEST_F(FlasherAgainstSimTest, LeakyCellIsAVerifyMismatchExitCode6) {
  // An image byte with a 0 bit; the leaky cell turns that bit back to 1.
  const std::uint32_t offset = 0x1234;
  image.bytes[offset] = 0x5A;  // bit 0 clear
  {
    DfuseFaults f;
    f.leaky_cell_address = kFlash + offset;
    f.leaky_cell_mask = 0x01;
    sim.set_faults(f);
  }
  EXPECT_EQ(flash(), 6) << message;
  EXPECT_NE(message.find("verify failed at 0x08001234: wrote 0x5a, read back 0x5b"), std::string::npos) << message;
  EXPECT_TRUE(sim.attached()) << "no leave after a failed verify";
  expect_monotone_progress();
}

TEST_F(FlasherAgainstSimTest, StalledRequestIsATransferFailure) {
  // The 10th GETSTATUS stalls (mid-erase): exit code 7, any other transfer failure.
  {
    DfuseFaults f;
    f.stall_request = dfu::kGetStatus;
    f.stall_occurrence = 10;
    sim.set_faults(f);
  }
  EXPECT_EQ(flash(), 7) << message;
  EXPECT_NE(message.find("stalled"), std::string::npos) << message;
}

TEST_F(FlasherAgainstSimTest, TooManyBlocksTouchesNothing) {
  // wTransferSize 2 bytes: 153700 / 2 = 76850 blocks, past block number 0xFFFF.
  DfuClient client(transport, sleep.function());
  FirmwareFlasher flasher(client, layout, 2, [](const FlashProgress&) {});
  try {
    flasher.flash(image);
    FAIL() << "flash() succeeded";
  } catch (const FlashError& e) {
    EXPECT_EQ(e.exit_code(), 3) << e.what();
  }
  EXPECT_EQ(transport.requests(), 0u);
  EXPECT_EQ(sim.flash().erase_count(), 0u);
}

TEST_F(FlasherAgainstSimTest, EveryAlternateStringIsADfuseLayout) {
  const Bytes config = control_in(sim.controller(), get_descriptor(descriptor::kConfiguration, 0, 255));
  // (first sector address, sector count, total bytes) per alternate, worked out by hand from the ROM's strings.
  const std::uint32_t expected[4][3] = {
      {0x08000000, 12, 1024 * 1024}, {0x1FFFC000, 1, 16}, {0x1FFF7800, 2, 512 + 16}, {0xFFFF0000, 1, 4}};
  for (int alt = 0; alt < 4; ++alt) {
    std::string error;
    const auto parsed =
        tools::usb::parse_dfuse_memory_layout(read_string(sim.controller(), config[9 * alt + 17]), error);
    ASSERT_TRUE(parsed.has_value()) << error;
    ASSERT_EQ(parsed->sectors.size(), expected[alt][1]);
    EXPECT_EQ(parsed->sectors.front().address, expected[alt][0]);
    std::uint64_t total = 0;
    for (const auto& sector : parsed->sectors) total += sector.size;
    EXPECT_EQ(total, expected[alt][2]);
  }
  EXPECT_EQ(layout.name, "Internal Flash");
  EXPECT_TRUE(layout.sectors[0].erasable && layout.sectors[0].writable && layout.sectors[0].readable);  // 'g'
}

}  // namespace
}  // namespace hadynet::usb::host_testing
