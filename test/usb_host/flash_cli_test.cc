// `hadynet flash` (this build's executable) as a child process against the
// simulated STM32 ROM DfuSe bootloader (test/dfuse_sim) on the testbed:
// from a bootloader already on the bus, through the whole DFU_DETACH flow
// from a running hand, and the documented failures with their exit codes
// (tools/usb/firmware_flasher.h: 3 doesn't fit, 4 vanished, 5 DFU status
// error, 6 verify mismatch, 7 other transfer failure). Also `--model`: a
// signed model image of the build's model (hadynet model-image) through the
// hand's own DFU interface, read back independently by dfu-util and run by
// the hand after a power-on; the hand's refusal in its own words; a file
// that is not a model image refused before any device is touched.
// Expected flash contents are the image file's bytes; expected erases come
// from the F405 sector table written out here (16,16,16,16,64,128.. KiB).
#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "test/dfuse_sim/stm32_rom_bootloader.h"
#include "test/usb/test_bytes.h"
#include "test/usb_host/child_process.h"
#include "test/usb_host/hand_device.h"
#include "test/usb_host/model_image_files.h"
#include "test/usb_host/test_records.h"
#include "test/usb_host/usb_testbed.h"
#include "tools/usb/model_image_file.h"

namespace hadynet::usb::host_testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using test_data::Bytes;
using test_data::pseudo_random;

constexpr std::uint8_t kRomDevnum = 3;  // where the bootloader appears (the hand is at 2)
// The sim's bwPollTimeout at 1 % of the datasheet's worst case: a 150 KiB
// image asks for 9.6 s of erase and 3.9 s of programming waits at 100 %,
// which the CLI really sleeps; 1 % keeps every wait non-zero (the DNBUSY
// polling path still runs) and the whole flash well under a second.
constexpr std::uint32_t kPollPercent = 1;
// Tolerance of a child's run: a flash here takes ~0.5 s (the detach flow's
// wait for the bootloader, up to 10 s in the CLI, ~0.2 s of it); the hang
// test costs libusb's 5 s control time-out (tools/usb/libusb_dfu.h); a
// --model download ~3 s (the hand's poll times: signature check 0.25 s,
// scaled erases and programming ~1 s, manifestation 2 s). 30 s only
// catches a hang.
constexpr auto kChildTimeout = 30s;
constexpr std::size_t kImageBytes = 150 * 1024;  // sectors 0..5 (0x08000000 .. 0x0803FFFF)

class CliFlash : public ::testing::Test {
 protected:
  void SetUp() override {
    bus_ = std::make_unique<UsbTestbed>();
    ASSERT_TRUE(bus_->ok()) << bus_->error();
    dir_ = fs::temp_directory_path() / ("hadynet_flash_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    image_ = pseudo_random(kImageBytes, 5);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  std::shared_ptr<Stm32RomBootloader> make_rom(const DfuseFaults& faults = {}) {
    auto rom = std::make_shared<Stm32RomBootloader>(faults);
    rom->set_poll_timeout_percent(kPollPercent);
    return rom;
  }
  void plug_rom(const DfuseFaults& faults = {}) {
    rom_ = make_rom(faults);
    ASSERT_TRUE(bus_->plug(kRomDevnum, rom_)) << bus_->error();
  }
  fs::path write(const std::string& name, const Bytes& bytes) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    return p;
  }
  static Bytes read(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return Bytes(std::istreambuf_iterator<char>(f), {});
  }
  ChildResult hadynet(std::vector<std::string> args, const std::function<void()>& tick = {}) {
    args.insert(args.begin(), HADYNET_CLI_EXECUTABLE);
    return run_child(*bus_, args, kChildTimeout, tick);
  }
  ChildResult flash_image(const std::function<void()>& tick = {}) {
    return hadynet({"flash", write("image.bin", image_).string()}, tick);
  }
  // The sim's flash from 0x08000000, `n` bytes (read under the bus lock).
  Bytes flash_bytes(std::size_t n) {
    Bytes b;
    bus_->locked([&] {
      const auto cells = rom_->flash().cells();
      b.assign(cells.begin(), cells.begin() + static_cast<std::ptrdiff_t>(n));
    });
    return b;
  }
  std::vector<std::size_t> erases() {
    std::vector<std::size_t> e;
    bus_->locked([&] {
      for (std::size_t i = 0; i < RomFlashModel::sector_count(); ++i) e.push_back(rom_->flash().erases_of(i));
    });
    return e;
  }

  std::unique_ptr<UsbTestbed> bus_;
  std::shared_ptr<Stm32RomBootloader> rom_;
  std::shared_ptr<HandDevice> hand_;
  fs::path dir_;
  Bytes image_;
};

// 150 KiB from 0x08000000 covers sectors 0..5 (4 x 16 + 64 + 128 KiB > 150 KiB > 128 KiB).
const std::vector<std::size_t> kSectors0To5Once = {1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0};

void expect_success(const ChildResult& r) {
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  EXPECT_NE(r.out.find("written and verified byte for byte, 6 sectors erased"), std::string::npos) << r.out;
  // Progress on stderr: each phase ends at 100 % with its byte count.
  EXPECT_NE(r.err.find("erase  ["), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("100%   " + std::to_string(kImageBytes) + "/" + std::to_string(kImageBytes) + " B"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("verify ["), std::string::npos) << r.err;
}

TEST_F(CliFlash, DevicesListsTheBootloader) {
  plug_rom();
  const ChildResult r = hadynet({"devices"});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  EXPECT_EQ(r.out.rfind("bootloader  bus 001 device 003", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("0483:df11"), std::string::npos) << r.out;
}

TEST_F(CliFlash, FlashesThroughABootloaderAlreadyThere) {
  plug_rom();
  const ChildResult r = flash_image();
  expect_success(r);
  EXPECT_FALSE(bus_->plugged(kRomDevnum)) << "leave: the bootloader drops off the bus";
  EXPECT_EQ(rom_->jump_address(), std::optional<std::uint32_t>(0x08000000u));
  EXPECT_EQ(flash_bytes(kImageBytes), image_);
  EXPECT_EQ(erases(), kSectors0To5Once);
  // The rest of sector 5 stays erased.
  const Bytes tail = flash_bytes(0x40000);
  EXPECT_EQ(Bytes(tail.begin() + kImageBytes, tail.end()), Bytes(0x40000 - kImageBytes, 0xFF));
}

// The hand reboots into the ROM on DFU_DETACH (leaves the bus); the ROM
// bootloader then enumerates at a new address, as on the real board.
TEST_F(CliFlash, DetachesTheHandThenFlashes) {
  hand_ = std::make_shared<HandDevice>();
  hand_->set_leave_on_detach(true);
  ASSERT_TRUE(bus_->plug(kHandDevnum, hand_)) << bus_->error();
  rom_ = make_rom();
  bool plugged = false;
  std::string plug_error;
  bus_->set_on_left([&](std::uint8_t devnum) {
    if (devnum != kHandDevnum || plugged) return;
    plugged = bus_->plug(kRomDevnum, rom_);
    if (!plugged) plug_error = bus_->error();
  });
  const ChildResult r = flash_image();
  ASSERT_TRUE(plugged) << plug_error << "\n" << r.describe();
  int detaches = 0;
  bus_->locked([&] { detaches = hand_->detach_requests(); });
  EXPECT_EQ(detaches, 1);
  EXPECT_NE(r.err.find("DFU_DETACH into the ROM bootloader"), std::string::npos) << r.err;
  expect_success(r);
  EXPECT_EQ(rom_->jump_address(), std::optional<std::uint32_t>(0x08000000u));
  EXPECT_EQ(flash_bytes(kImageBytes), image_);
  EXPECT_EQ(erases(), kSectors0To5Once);
}

// ---- failures: exit code and message through the CLI ----

// Block numbers are DfuSe wValues: block 2 is the first 2048 bytes.
TEST_F(CliFlash, VanishedDeviceExitsFourAndSaysHowToRecover) {
  DfuseFaults faults;
  faults.vanish_after_block = 12;  // 11 blocks (22528 bytes) programmed
  plug_rom(faults);
  const ChildResult r = flash_image();
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 4) << r.describe();
  EXPECT_NE(r.err.find("the device vanished"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("6 erased sector(s)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the old firmware is gone"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("BOOT0"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("flashed"), std::string::npos) << r.out;
}

TEST_F(CliFlash, StatusErrorExitsFiveAndNamesStateAndStatus) {
  DfuseFaults faults;
  faults.error_at_block = 20;
  faults.error_status = dfu::Status::kErrProg;
  plug_rom(faults);
  const ChildResult r = flash_image();
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 5) << r.describe();
  EXPECT_NE(r.err.find("block 20: the device reports errPROG"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("in state dfuERROR (10)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("BOOT0"), std::string::npos) << r.err;
}

// A cell that loses a bit after the ROM's own program check: only the
// CLI's read-back finds it.
TEST_F(CliFlash, LeakyCellExitsSixWithTheAddress) {
  constexpr std::uint32_t kOffset = 0x1234;
  image_[kOffset] = 0x00;  // every bit programmed: the leak (bit 0 back to 1) shows
  DfuseFaults faults;
  faults.leaky_cell_address = 0x08000000u + kOffset;
  faults.leaky_cell_mask = 0x01;
  plug_rom(faults);
  const ChildResult r = flash_image();
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 6) << r.describe();
  EXPECT_NE(r.err.find("verify failed at 0x08001234: wrote 0x00, read back 0x01"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("do not run this firmware"), std::string::npos) << r.err;
  EXPECT_TRUE(bus_->plugged(kRomDevnum)) << "no leave after a failed verify";
}

TEST_F(CliFlash, ImageThatDoesNotFitExitsThreeAndErasesNothing) {
  plug_rom();
  image_ = pseudo_random(1024 * 1024 + 1, 9);  // one byte more than the F405's 1 MiB
  const ChildResult r = flash_image();
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 3) << r.describe();
  EXPECT_NE(r.err.find("does not fit inside of the device's"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Nothing was written."), std::string::npos) << r.err;
  EXPECT_EQ(erases(), std::vector<std::size_t>(12, 0));
  std::size_t downloads = 1;
  bus_->locked([&] { downloads = rom_->dfu().downloads(); });
  EXPECT_EQ(downloads, 0u);
}

// EP0 faults injected by the testbed once 40 blocks' worth of packets have
// gone by (32 data packets per 2048-byte block): never success, bounded
// time. A STALL ends at once; a hung transfer ends at libusb's 5 s control
// time-out (tools/usb/libusb_dfu.h). Both are "other transfer failure", 7.
void expect_transfer_failure(const ChildResult& r, bool armed) {
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_TRUE(armed) << r.describe();
  EXPECT_EQ(r.exit_code, 7) << r.describe();
  EXPECT_NE(r.err.find("USB transfer failed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("BOOT0"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("flashed"), std::string::npos) << r.out;
}

TEST_F(CliFlash, StallMidWayFailsWithSeven) {
  plug_rom();
  bool armed = false;
  const ChildResult r = flash_image([&] {
    if (!armed && bus_->packets(kRomDevnum).of(0x00) >= 40 * 32) {
      bus_->fail_next_transfer(kRomDevnum, 0x00, EPIPE);
      armed = true;
    }
  });
  expect_transfer_failure(r, armed);
}

TEST_F(CliFlash, HungTransferMidWayFailsWithSevenInBoundedTime) {
  plug_rom();
  bool armed = false;
  const ChildResult r = flash_image([&] {
    if (!armed && bus_->packets(kRomDevnum).of(0x00) >= 40 * 32) {
      bus_->hang_next_transfer(kRomDevnum, 0x00);
      armed = true;
    }
  });
  expect_transfer_failure(r, armed);
  // Tolerance: the 5 s time-out plus the flash so far (~1 s); 12 s would mean a second wait.
  EXPECT_LT(r.elapsed_s, 12.0) << r.describe();
}

// --model through the hand's DFU-mode interface (docs/usb.md "Model
// images"): what the file says, the transfer, the read-back, the slot the
// hand names; then read back by dfu-util, a client that is not ours; then
// the hand after a power-on runs it, and `hadynet devices` says so.
TEST_F(CliFlash, ModelImageGoesIntoAFreeSlotAndRunsAfterAPowerOn) {
  hand_ = std::make_shared<HandDevice>();
  ASSERT_TRUE(bus_->plug(kHandDevnum, hand_)) << bus_->error();
  const fs::path image = make_model_image(*bus_, dir_, 2);
  const Bytes file = read(image);
  ASSERT_GT(file.size(), 256u);
  const ChildResult r = hadynet({"flash", "--model", image.string()});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  char shape[17];
  std::snprintf(shape, sizeof shape, "%016llx", static_cast<unsigned long long>(Q::kShapeId));
  EXPECT_NE(r.out.find("model image " + image.string() + ": sequence 2, q15, shape id " + shape +
                       " (this build's firmware), payload " + std::to_string(file.size() - 256) + " bytes"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("-- the DEVELOPMENT key"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(std::to_string(file.size()) + " bytes sent to hand " + std::string(kFixtureSerial) +
                       " and read back byte for byte: image sequence 2 written to slot A: the boot rule tries it at "
                       "the next reset"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("the new model runs after the next reset or power-up"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("verify ["), std::string::npos) << r.err;
  bus_->locked([&] {
    EXPECT_EQ(hand_->slot_status(model_update::SlotId::kA).state, model_update::SlotState::kValid);
    EXPECT_EQ(hand_->boot_choice().source, model_update::ModelSource::kFactory) << "until the reset";
  });
  if (!std::string(DFU_UTIL_EXECUTABLE).empty() && fs::exists(DFU_UTIL_EXECUTABLE)) {
    const fs::path back = dir_ / "readback.img";
    const ChildResult up = run_child(
        *bus_, {DFU_UTIL_EXECUTABLE, "-d", "1209:0001", "-i", "4", "-a", "0", "-U", back.string()}, kChildTimeout);
    ASSERT_EQ(up.exit_code, 0) << up.describe();
    EXPECT_EQ(read(back), file);
  }
  // Power-on: the same flash in a new hand; the boot rule runs the image
  // (the app's self-test passes: hadynet model-image computed its checksum).
  std::vector<std::uint8_t> cells;
  bus_->locked([&] { cells = hand_->flash_cells(); });
  bus_->unplug(kHandDevnum);
  hand_ = std::make_shared<HandDevice>(&cells);
  ASSERT_TRUE(bus_->plug(kHandDevnum, hand_)) << bus_->error();
  const ChildResult d = hadynet({"devices"});
  ASSERT_EQ(d.exit_code, 0) << d.describe();
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx",
                static_cast<unsigned long long>(
                    tools::usb::check_model_image_bytes(file, image.string()).header.model_hash));
  EXPECT_NE(d.out.find(std::string("  model ") + hash + " (slot A, sequence 2)  "), std::string::npos) << d.out;
}

// The hand's refusal, in its own words, exit 5; nothing else changes.
TEST_F(CliFlash, ModelImageTheHandRefusesIsReportedInItsWords) {
  hand_ = std::make_shared<HandDevice>();
  ASSERT_TRUE(bus_->plug(kHandDevnum, hand_)) << bus_->error();
  const fs::path key = make_other_key(*bus_, dir_);
  const fs::path image = make_model_image(*bus_, dir_, 2, key);
  const ChildResult r = hadynet({"flash", "--model", image.string()});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 5) << r.describe();
  EXPECT_EQ(r.out.find("DEVELOPMENT"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("hadynet flash --model: the image was not taken: signed by another key (block 0: the device "
                       "reports errFILE (file failed verification) (status 0x02) in state dfuERROR (10)); the model "
                       "in use and the boot choice are unchanged"),
            std::string::npos)
      << r.err;
  bus_->locked([&] {
    EXPECT_EQ(hand_->slot_status(model_update::SlotId::kA).state, model_update::SlotState::kEmpty);
    EXPECT_EQ(hand_->slot_status(model_update::SlotId::kB).state, model_update::SlotState::kEmpty);
  });
  // The hand was left usable: the next image goes in.
  const ChildResult again = hadynet({"flash", "--model", make_model_image(*bus_, dir_, 3).string(), "--quiet"});
  EXPECT_EQ(again.exit_code, 0) << again.describe();
}

// A hand without model flash STALLs the first DNLOAD; the CLI asks for the
// status and prints the hand's reason (errTARGET), exit 5.
TEST_F(CliFlash, AHandWithoutModelSlotsSaysSo) {
  hand_ = std::make_shared<HandDevice>(nullptr, /*model_slots=*/false);
  ASSERT_TRUE(bus_->plug(kHandDevnum, hand_)) << bus_->error();
  const ChildResult r = hadynet({"flash", "--model", make_model_image(*bus_, dir_, 2).string(), "--quiet"});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 5) << r.describe();
  EXPECT_NE(r.err.find("the image was not taken: this device has no model slots: it takes no model images"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("errTARGET"), std::string::npos) << r.err;
}

// A file that is not a model image: refused, with the reason, before any
// device is looked for (no hand on the bus here).
TEST_F(CliFlash, AFileThatIsNotAModelImageIsRefusedBeforeAnyDevice) {
  const ChildResult r = hadynet({"flash", "--model", write("model.bin", pseudo_random(3000, 17)).string()});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 1) << r.describe();
  EXPECT_NE(r.err.find("model.bin: not a model image: not a model image (magic is not \"HYDM\")"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("nothing was sent"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("no HADYNET hand"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace hadynet::usb::host_testing
