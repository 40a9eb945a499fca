// dfu-util (Debian's 0.11, a peer client we do not control) as a child
// process against the hand on the testbed: the DFU interfaces it lists, a
// signed model image (this build's `hadynet model-image` of the build's
// model) downloaded into the free slot and uploaded back byte for byte
// (docs/usb.md "Model images"), an image the hand refuses, and EP0 faults
// during the transfer.
#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "test/usb_host/child_process.h"
#include "test/usb_host/hand_device.h"
#include "test/usb_host/model_image_files.h"
#include "test/usb_host/test_records.h"
#include "test/usb_host/usb_testbed.h"

namespace hadynet::usb::host_testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// Tolerance: dfu-util sleeps each bwPollTimeout the device asks (the
// header's signature check 0.25 s, the hand's scaled erases and programming
// ~1 s, manifestation 2 s plus dfu-util's own 1 s) and its own control
// time-out is 5 s: a download takes ~4 s here. 30 s only catches a hang.
constexpr auto kChildTimeout = 30s;

class DfuUtil : public ::testing::Test {
 protected:
  void SetUp() override {
    if (std::string(DFU_UTIL_EXECUTABLE).empty() || !fs::exists(DFU_UTIL_EXECUTABLE)) {
      GTEST_SKIP() << "dfu-util not installed";
    }
    bus_ = std::make_unique<UsbTestbed>();
    ASSERT_TRUE(bus_->ok()) << bus_->error();
    hand_ = std::make_shared<HandDevice>();
    ASSERT_TRUE(bus_->plug(kHandDevnum, hand_)) << bus_->error();
    dir_ = fs::temp_directory_path() / ("hadynet_dfu_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  // A signed image of the build's model that the hand takes (sequence 2).
  fs::path model_image() { return make_model_image(*bus_, dir_, 2); }

  ChildResult dfu_util(std::vector<std::string> args, const std::function<void()>& tick = {}) {
    args.insert(args.begin(), DFU_UTIL_EXECUTABLE);
    return run_child(*bus_, args, kChildTimeout, tick);
  }
  static std::vector<std::uint8_t> read(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(f), {});
  }

  std::unique_ptr<UsbTestbed> bus_;
  std::shared_ptr<HandDevice> hand_;
  fs::path dir_;
};

TEST_F(DfuUtil, ListsTheRuntimeAndModelInterfaces) {
  const ChildResult r = dfu_util({"-l"});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_EQ(r.exit_code, 0) << r.describe();
  const std::string serial = std::string("serial=\"") + kFixtureSerial + "\"";
  const auto has_line = [&](const std::string& a, const std::string& b, const std::string& c) {
    for (std::size_t at = r.out.find(a); at != std::string::npos; at = r.out.find(a, at + 1)) {
      const std::string line = r.out.substr(at, r.out.find('\n', at) - at);
      if (line.find(b) != std::string::npos && line.find(c) != std::string::npos &&
          line.find(serial) != std::string::npos) {
        return true;
      }
    }
    return false;
  };
  EXPECT_TRUE(has_line("Found Runtime: [1209:0001]", "intf=3, ",
                       "name=\"HADYNET firmware update (DFU detach to ROM DfuSe)\""))
      << r.out;
  EXPECT_TRUE(has_line("Found DFU: [1209:0001]", "intf=4, path=\"1-2\", alt=0,",
                       "name=\"HADYNET model update (signed image)\""))
      << r.out;
  EXPECT_TRUE(has_line("Found DFU: [1209:0001]", "intf=4, path=\"1-2\", alt=1,",
                       "name=\"HADYNET model in use, read only\""))
      << r.out;
}

TEST_F(DfuUtil, ModelImageDownloadThenUploadIsByteForByte) {
  const fs::path in = model_image();
  const std::vector<std::uint8_t> image = read(in);
  ASSERT_GT(image.size(), 256u);
  const ChildResult down = dfu_util({"-d", "1209:0001", "-i", "4", "-a", "0", "-D", in.string()});
  ASSERT_TRUE(down.started && !down.timed_out) << down.describe();
  ASSERT_EQ(down.exit_code, 0) << down.describe();
  const fs::path back = dir_ / "readback.img";
  const ChildResult up = dfu_util({"-d", "1209:0001", "-i", "4", "-a", "0", "-U", back.string()});
  ASSERT_TRUE(up.started && !up.timed_out) << up.describe();
  ASSERT_EQ(up.exit_code, 0) << up.describe();
  EXPECT_EQ(read(back), image);
  // Alternate 1 is the model in use: the factory model until a reset, no slot.
  const fs::path running = dir_ / "running.img";
  const ChildResult r1 = dfu_util({"-d", "1209:0001", "-i", "4", "-a", "1", "-U", running.string()});
  ASSERT_EQ(r1.exit_code, 0) << r1.describe();
  EXPECT_TRUE(read(running).empty());
}

// An image signed by another key: the hand refuses its header before
// erasing anything; dfu-util reports the DFU status and fails.
TEST_F(DfuUtil, AnImageOfAnotherKeyIsRefusedWithErrFile) {
  const fs::path key = make_other_key(*bus_, dir_);
  const fs::path in = make_model_image(*bus_, dir_, 2, key);
  const ChildResult r = dfu_util({"-d", "1209:0001", "-i", "4", "-a", "0", "-D", in.string()});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_NE(r.exit_code, 0) << r.describe();
  const std::string all = r.out + r.err;
  EXPECT_NE(all.find("status(2)"), std::string::npos) << all;  // errFILE
  EXPECT_EQ(all.find("Done!"), std::string::npos) << all;
  bus_->locked([&] {
    EXPECT_EQ(hand_->slot_status(model_update::SlotId::kA).state, model_update::SlotState::kEmpty);
    EXPECT_EQ(hand_->slot_status(model_update::SlotId::kB).state, model_update::SlotState::kEmpty);
  });
}

// dfu-util 0.11 takes the first DFU functional descriptor of the
// configuration (the runtime interface's) for every interface: its
// wTransferSize must be the model interface's, or the documented command
// line fails with STALLed blocks (firmware/usb/dfu_runtime.h).
TEST_F(DfuUtil, UsesTheModelInterfacesTransferSizeWithoutBeingTold) {
  const fs::path in = model_image();
  const ChildResult r = dfu_util({"-d", "1209:0001", "-i", "4", "-a", "0", "-D", in.string()});
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_NE(r.out.find("Device returned transfer size 256"), std::string::npos) << r.out;
  EXPECT_EQ(r.exit_code, 0) << r.describe();
}

// EP0 faults in the middle of a download (after a few DNLOAD blocks): dfu-util
// must end in bounded time with a non-zero exit, and no slot holds an image
// afterwards (the header is programmed last: docs/usb.md).
void expect_failed_download(const ChildResult& r) {
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  EXPECT_NE(r.exit_code, 0) << r.describe();
  EXPECT_EQ(r.err.find("Done!"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("Done!"), std::string::npos) << r.out;
}

TEST_F(DfuUtil, StallDuringDownloadFails) {
  const fs::path in = model_image();
  bool armed = false;
  const ChildResult r = dfu_util({"-d", "1209:0001", "-i", "4", "-a", "0", "-D", in.string()}, [&] {
    if (!armed && bus_->packets(kHandDevnum).of(0x00) >= 8) {  // 2 blocks of 4 packets in
      bus_->fail_next_transfer(kHandDevnum, 0x00, EPIPE);
      armed = true;
    }
  });
  EXPECT_TRUE(armed);
  expect_failed_download(r);
  bus_->locked([&] {
    EXPECT_NE(hand_->slot_status(model_update::SlotId::kA).state, model_update::SlotState::kValid);
  });
}

TEST_F(DfuUtil, TimeoutDuringDownloadFailsInBoundedTime) {
  const fs::path in = model_image();
  bool armed = false;
  const ChildResult r = dfu_util({"-d", "1209:0001", "-i", "4", "-a", "0", "-D", in.string()}, [&] {
    if (!armed && bus_->packets(kHandDevnum).of(0x00) >= 8) {
      bus_->hang_next_transfer(kHandDevnum, 0x00);
      armed = true;
    }
  });
  EXPECT_TRUE(armed);
  expect_failed_download(r);
}

// A short packet in an UPLOAD data stage is, for DFU 1.1, the end of the
// file: dfu-util cannot tell it from the real end and exits 0 with a short
// file. The image header's payload length is what exposes it (hadynet
// flash --model compares the whole read-back; recorded here so the
// limitation stays visible).
TEST_F(DfuUtil, ShortUploadBlockIsIndistinguishableFromTheEndForDfuUtil) {
  const fs::path in = model_image();
  const std::vector<std::uint8_t> image = read(in);
  ASSERT_EQ(dfu_util({"-d", "1209:0001", "-i", "4", "-a", "0", "-D", in.string()}).exit_code, 0);
  bool armed = false;
  const std::uint64_t before = bus_->packets(kHandDevnum).of(0x80);
  const fs::path back = dir_ / "readback.img";
  const ChildResult r = dfu_util({"-d", "1209:0001", "-i", "4", "-a", "0", "-U", back.string()}, [&] {
    if (!armed && bus_->packets(kHandDevnum).of(0x80) >= before + 8) {  // two upload blocks in
      bus_->short_next_in(kHandDevnum, 0x00, 10);
      armed = true;
    }
  });
  ASSERT_TRUE(r.started && !r.timed_out) << r.describe();
  ASSERT_TRUE(armed);
  const std::vector<std::uint8_t> got = read(back);
  ASSERT_GE(got.size(), 256u);
  EXPECT_LT(got.size(), image.size());
  const std::uint32_t length = got[24] | (got[25] << 8) | (got[26] << 16) | (static_cast<std::uint32_t>(got[27]) << 24);
  EXPECT_NE(got.size(), 256u + length) << "the header's payload length exposes the truncation";
}

}  // namespace
}  // namespace hadynet::usb::host_testing
