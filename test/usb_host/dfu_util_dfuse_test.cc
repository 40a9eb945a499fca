// dfu-util (Debian's 0.11, a DfuSe client nobody here wrote) as a child
// process against the simulated STM32 ROM bootloader (test/dfuse_sim) on
// the testbed: the documented firmware command line of docs/usb.md
// (`-a 0 -s 0x08000000:leave -D`), the listing of the four alternates with
// their DfuSe memory strings (AN3156, written out here), and an upload.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "test/dfuse_sim/stm32_rom_bootloader.h"
#include "test/usb/test_bytes.h"
#include "test/usb_host/child_process.h"
#include "test/usb_host/usb_testbed.h"

namespace hadynet::usb::host_testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using test_data::Bytes;
using test_data::pseudo_random;

constexpr std::uint8_t kRomDevnum = 5;
// 1 % of the datasheet's worst-case bwPollTimeout: dfu-util sleeps every
// wait the device reports (9.6 s of erases and 2.6 s of programming for the
// image below at 100 %); 1 % keeps the waits non-zero and the run short.
constexpr std::uint32_t kPollPercent = 1;
// Tolerance of a dfu-util run: ~0.5 s here; 20 s only catches a hang.
constexpr auto kChildTimeout = 20s;
constexpr std::size_t kImageBytes = 100 * 1024 + 123;  // sectors 0..4, a short last block

class DfuUtilDfuse : public ::testing::Test {
 protected:
  void SetUp() override {
    if (std::string(DFU_UTIL_EXECUTABLE).empty() || !fs::exists(DFU_UTIL_EXECUTABLE)) {
      GTEST_SKIP() << "dfu-util not installed";
    }
    bus_ = std::make_unique<UsbTestbed>();
    ASSERT_TRUE(bus_->ok()) << bus_->error();
    rom_ = std::make_shared<Stm32RomBootloader>();
    rom_->set_poll_timeout_percent(kPollPercent);
    ASSERT_TRUE(bus_->plug(kRomDevnum, rom_)) << bus_->error();
    dir_ = fs::temp_directory_path() / ("hadynet_dfuse_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  ChildResult dfu_util(std::vector<std::string> args) {
    args.insert(args.begin(), DFU_UTIL_EXECUTABLE);
    return run_child(*bus_, args, kChildTimeout);
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
  Bytes flash_bytes(std::size_t n) {
    Bytes b;
    bus_->locked([&] {
      const auto cells = rom_->flash().cells();
      b.assign(cells.begin(), cells.begin() + static_cast<std::ptrdiff_t>(n));
    });
    return b;
  }

  std::unique_ptr<UsbTestbed> bus_;
  std::shared_ptr<Stm32RomBootloader> rom_;
  fs::path dir_;
};

TEST_F(DfuUtilDfuse, ListsTheFourAlternatesWithTheirMemoryStrings) {
  const ChildResult r = dfu_util({"-l"});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  const char* const names[] = {
      "@Internal Flash  /0x08000000/04*016Kg,01*064Kg,07*128Kg",
      "@Option Bytes  /0x1FFFC000/01*016 e",
      "@OTP Memory /0x1FFF7800/01*512 e,01*016 e",
      "@Device Feature/0xFFFF0000/01*004 e",
  };
  for (int alt = 0; alt < 4; ++alt) {
    const std::string want = "Found DFU: [0483:df11] ver=2200, devnum=5, cfg=1, intf=0, path=\"1-5\", alt=" +
                             std::to_string(alt) + ", name=\"" + names[alt] + "\"";
    EXPECT_NE(r.out.find(want), std::string::npos) << want << "\n" << r.out;
  }
}

TEST_F(DfuUtilDfuse, DownloadWithLeaveWritesTheImage) {
  const Bytes image = pseudo_random(kImageBytes, 3);
  const ChildResult r =
      dfu_util({"-d", "0483:df11", "-a", "0", "-s", "0x08000000:leave", "-D", write("image.bin", image).string()});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  EXPECT_EQ(flash_bytes(kImageBytes), image);
  EXPECT_EQ(rom_->jump_address(), std::optional<std::uint32_t>(0x08000000u)) << r.describe();
  EXPECT_FALSE(bus_->plugged(kRomDevnum)) << "leave: the bootloader drops off the bus";
  // dfu-util erases page by page what the image covers: sectors 0..4 once each.
  for (std::size_t s = 0; s < RomFlashModel::sector_count(); ++s) {
    EXPECT_EQ(rom_->flash().erases_of(s), s <= 4 ? 1u : 0u) << "sector " << s;
  }
}

TEST_F(DfuUtilDfuse, UploadReadsTheFlashBack) {
  const Bytes image = pseudo_random(kImageBytes, 4);
  bus_->locked([&] { rom_->flash().fill(0x08000000, image); });
  const fs::path out = dir_ / "out.bin";
  const ChildResult r = dfu_util(
      {"-d", "0483:df11", "-a", "0", "-s", "0x08000000:" + std::to_string(kImageBytes), "-U", out.string()});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  EXPECT_EQ(read(out), image);
  EXPECT_TRUE(bus_->plugged(kRomDevnum)) << "no leave on an upload";
}

}  // namespace
}  // namespace hadynet::usb::host_testing
