// DFU 1.1 through the host backend: the runtime interface's detach, and the
// DFU-mode interface's whole state machine writing model images into the
// simulated NOR flash (STM32F405 layout). The host side here behaves like
// dfu-util 0.11 (DNLOAD, then GETSTATUS until dfuDNLOAD-IDLE or dfuERROR,
// sleeping bwPollTimeout = calling service(); zero-length DNLOAD; GETSTATUS
// until dfuIDLE). Every expectation is exact: states, status codes, bytes.
#include <gtest/gtest.h>

#include <cstring>

#include "test/usb/test_bytes.h"
#include "usb_test_device.h"

namespace hadynet::usb::testing {
namespace {

constexpr std::uint8_t kDfu = composite::kDfuModeInterface;
constexpr std::uint8_t kRuntime = composite::kDfuRuntimeInterface;
using test_data::pseudo_random;
using dfu::State;
using dfu::Status;

struct DfuStatus {
  bool ok = false;
  Status status = Status::kOk;
  std::uint32_t poll_ms = 0;
  State state = State::kAppIdle;
};

SetupPacket dfu_req(bool in, std::uint8_t request, std::uint16_t value, std::uint16_t length,
                    std::uint8_t interface = kDfu) {
  return UsbTestDevice::class_interface(in, request, value, interface, length);
}

DfuStatus get_status(UsbTestDevice& dev, std::uint8_t interface = kDfu) {
  Bytes in;
  DfuStatus s;
  s.ok = dev.control(dfu_req(true, dfu::kGetStatus, 0, 6, interface), {}, &in).ok() && in.size() == 6;
  if (!s.ok) return s;
  s.status = static_cast<Status>(in[0]);
  s.poll_ms = in[1] | (in[2] << 8) | (in[3] << 16);
  s.state = static_cast<State>(in[4]);
  return s;
}

State get_state(UsbTestDevice& dev) {
  Bytes in;
  EXPECT_TRUE(dev.control(dfu_req(true, dfu::kGetState, 0, 1), {}, &in).ok());
  return in.size() == 1 ? static_cast<State>(in[0]) : State::kAppIdle;
}

struct DownloadTrace {
  std::vector<State> states;           // every GETSTATUS state seen, in order
  std::vector<std::uint32_t> polls;    // every bwPollTimeout seen
  DfuStatus final_status;
  std::size_t blocks_sent = 0;
};

// dfu-util's download loop. Stops at the first dfuERROR (and returns it).
DownloadTrace download(UsbTestDevice& dev, const Bytes& file, std::size_t block = kDfuTransferSize,
                       std::uint16_t first_block = 0) {
  DownloadTrace t;
  const auto poll_until = [&](State done) {
    for (int guard = 0; guard < 20; ++guard) {
      const DfuStatus s = get_status(dev);
      t.final_status = s;
      if (!s.ok) return false;
      t.states.push_back(s.state);
      t.polls.push_back(s.poll_ms);
      if (s.state == State::kError) return false;
      if (s.state == done) return true;
      dev.usb->service();  // the host sleeps bwPollTimeout; the device works
    }
    return false;
  };
  std::uint16_t number = first_block;
  for (std::size_t off = 0; off < file.size(); off += block) {
    const std::size_t n = std::min(block, file.size() - off);
    const Bytes data(file.begin() + static_cast<long>(off), file.begin() + static_cast<long>(off + n));
    if (!dev.control(dfu_req(false, dfu::kDnload, number++, static_cast<std::uint16_t>(n)), data).ok()) {
      t.final_status.ok = false;
      return t;
    }
    ++t.blocks_sent;
    if (!poll_until(State::kDnloadIdle)) return t;
  }
  if (!dev.control(dfu_req(false, dfu::kDnload, number, 0)).ok()) {
    t.final_status.ok = false;
    return t;
  }
  poll_until(State::kIdle);
  return t;
}

Bytes upload(UsbTestDevice& dev, std::uint16_t block = kDfuTransferSize) {
  Bytes all;
  for (std::uint16_t number = 0; number < 5000; ++number) {
    Bytes in;
    if (!dev.control(dfu_req(true, dfu::kUpload, number, block), {}, &in).ok()) {
      ADD_FAILURE() << "UPLOAD block " << number << " stalled";
      break;
    }
    all.insert(all.end(), in.begin(), in.end());
    if (in.size() < block) break;
  }
  return all;
}

Bytes slot_bytes(const UsbTestDevice& dev, const flash::FlashRegion& slot, std::size_t n) {
  const auto c = dev.flash.contents();
  return Bytes(c.begin() + slot.offset, c.begin() + slot.offset + static_cast<long>(n));
}

TEST(UsbDfuRuntime, DetachCallsTheBoardHookAfterTheStatusStage) {
  UsbTestDevice dev;
  dev.enumerate();
  const DfuStatus s = get_status(dev, kRuntime);
  ASSERT_TRUE(s.ok);
  EXPECT_EQ(s.state, State::kAppIdle);
  EXPECT_EQ(s.status, Status::kOk);
  // SETUP alone does not detach: the host has not seen success yet.
  dev.controller.setup(dfu_req(false, dfu::kDetach, 1000, 0, kRuntime));
  EXPECT_EQ(dev.hook.calls, 0);
  std::uint8_t buf[64];
  std::size_t n = 0;
  ASSERT_EQ(dev.controller.in_token(0x80, buf, n), Handshake::kAck);
  EXPECT_EQ(dev.hook.calls, 1);
  EXPECT_EQ(dev.hook.last_timeout_ms, 1000);
  EXPECT_EQ(dev.usb->dfu_runtime().state(), State::kAppDetach);
  // Once detached, a second DETACH is refused; a wrong GETSTATUS length too.
  EXPECT_TRUE(dev.control(dfu_req(false, dfu::kDetach, 1000, 0, kRuntime)).stalled());
  EXPECT_TRUE(dev.control(dfu_req(true, dfu::kGetStatus, 0, 5, kRuntime)).stalled());
  EXPECT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 0, 4, kRuntime), Bytes(4, 0)).stalled());
  EXPECT_EQ(dev.hook.calls, 1);
}

TEST(UsbDfuMode, DownloadAndUploadRoundTripByteForByte) {
  UsbTestDevice dev;
  dev.enumerate();
  // 150 KiB: crosses slot B's first 128 KiB sector into the second.
  const Bytes file = test_data::model_image_file(pseudo_random(150 * 1024, 1));
  const DownloadTrace t = download(dev, file);
  ASSERT_TRUE(t.final_status.ok);
  EXPECT_EQ(t.final_status.state, State::kIdle);
  EXPECT_EQ(t.final_status.status, Status::kOk);
  EXPECT_EQ(dev.usb->dfu_mode().images_written(), 1u);
  // States: each block DNBUSY then DNLOAD-IDLE; after the last, MANIFEST (7)
  // then IDLE; never MANIFEST-WAIT-RESET (8).
  const std::size_t blocks = (file.size() + 255) / 256;
  ASSERT_EQ(t.states.size(), 2 * blocks + 2);
  for (std::size_t b = 0; b < blocks; ++b) {
    EXPECT_EQ(t.states[2 * b], State::kDnBusy) << b;
    EXPECT_EQ(t.states[2 * b + 1], State::kDnloadIdle) << b;
  }
  EXPECT_EQ(t.states[2 * blocks], State::kManifest);
  EXPECT_EQ(t.states[2 * blocks + 1], State::kIdle);
  // bwPollTimeout: the first block erases a 128 KiB sector (4000 ms worst
  // case) + 256 bytes at 25 us/byte (7 ms rounded up); plain blocks 7 ms;
  // the block entering the second sector erases it.
  EXPECT_EQ(t.polls[0], 4000u + 7u);
  EXPECT_EQ(t.polls[2], 7u);
  // Stream offset 128 KiB (slot offset = stream offset) starts block 512.
  const std::size_t crossing = 128 * 1024 / 256;
  EXPECT_EQ(t.polls[2 * (crossing - 1)], 7u);
  EXPECT_EQ(t.polls[2 * crossing], 4000u + 7u);
  EXPECT_EQ(dev.flash.erase_count(), 2u) << "exactly the slot's two sectors";
  // The slot holds the file as sent.
  EXPECT_EQ(slot_bytes(dev, kSlotB, file.size()), file);
  // Nothing outside the slot was touched.
  const auto c = dev.flash.contents();
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (i >= kSlotB.offset && i < kSlotB.offset + file.size()) continue;
    ASSERT_EQ(c[i], 0xFF) << "offset " << i;
  }
  // Upload returns it, with the standard and an odd block size.
  EXPECT_EQ(upload(dev), file);
  EXPECT_EQ(get_state(dev), State::kIdle);
  EXPECT_EQ(upload(dev, 100), file);
}

TEST(UsbDfuMode, AnImageOfExactlyTheSlotSizeFitsAndOneByteMoreDoesNot) {
  UsbTestDevice dev;
  dev.enumerate();
  const std::uint32_t max_payload = kSlotB.size - 16;
  // Only the header matters for the size check: send the first block.
  Bytes header = test_data::model_image_file({}, 0, max_payload + 1);
  header.resize(16);
  const DownloadTrace t = download(dev, header);
  EXPECT_EQ(t.final_status.state, State::kError);
  EXPECT_EQ(t.final_status.status, Status::kErrAddress);
  EXPECT_EQ(dev.flash.erase_count(), 0u) << "refused before anything was erased";
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kClrStatus, 0, 0)).ok());
  const Bytes full = test_data::model_image_file(pseudo_random(max_payload, 2));
  const DownloadTrace ok = download(dev, full);
  EXPECT_EQ(ok.final_status.state, State::kIdle);
  EXPECT_EQ(ok.final_status.status, Status::kOk);
  EXPECT_EQ(upload(dev), full);
}

TEST(UsbDfuMode, TooLargeImageLeavesThePreviousImageIntact) {
  UsbTestDevice dev;
  dev.enumerate();
  const Bytes first = test_data::model_image_file(pseudo_random(3000, 3));
  ASSERT_EQ(download(dev, first).final_status.state, State::kIdle);
  const std::uint64_t erases = dev.flash.erase_count();
  const Bytes huge = test_data::model_image_file(pseudo_random(64, 4), 0, kSlotB.size);  // claims a payload as large as the slot
  const DownloadTrace t = download(dev, huge);
  EXPECT_EQ(t.final_status.status, Status::kErrAddress);
  EXPECT_EQ(t.blocks_sent, 1u);
  EXPECT_EQ(dev.flash.erase_count(), erases);
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kClrStatus, 0, 0)).ok());
  EXPECT_EQ(upload(dev), first);
}

TEST(UsbDfuMode, BadCrcIsRefusedAtManifestationAndLeavesNoImage) {
  UsbTestDevice dev;
  dev.enumerate();
  const DownloadTrace t = download(dev, test_data::model_image_file(pseudo_random(5000, 5), /*crc_xor=*/1));
  EXPECT_EQ(t.final_status.state, State::kError);
  EXPECT_EQ(t.final_status.status, Status::kErrFile);
  EXPECT_EQ(t.states.back(), State::kError);
  EXPECT_EQ(t.states[t.states.size() - 2], State::kManifest);
  EXPECT_EQ(slot_bytes(dev, kSlotB, 16), Bytes(16, 0xFF)) << "the header is never written";
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kClrStatus, 0, 0)).ok());
  EXPECT_TRUE(upload(dev).empty());
}

TEST(UsbDfuMode, FlashErrorsBecomeDfuStatusCodes) {
  {
    UsbTestDevice dev;
    dev.enumerate();
    dev.flash.fail_write_at(1);  // the first operation is the slot's first erase
    const DownloadTrace t = download(dev, test_data::model_image_file(pseudo_random(1000, 6)));
    EXPECT_EQ(t.final_status.state, State::kError);
    EXPECT_EQ(t.final_status.status, Status::kErrErase);
  }
  {
    UsbTestDevice dev;
    dev.enumerate();
    dev.flash.fail_write_at(3);  // erase, program block 0, program block 1 (fails)
    const DownloadTrace t = download(dev, test_data::model_image_file(pseudo_random(1000, 6)));
    EXPECT_EQ(t.final_status.state, State::kError);
    EXPECT_EQ(t.final_status.status, Status::kErrWrite);
    EXPECT_EQ(t.blocks_sent, 2u);
    // CLRSTATUS and a new download (the flash works again) succeed.
    ASSERT_TRUE(dev.control(dfu_req(false, dfu::kClrStatus, 0, 0)).ok());
    EXPECT_EQ(get_state(dev), State::kIdle);
    const Bytes file = test_data::model_image_file(pseudo_random(1000, 7));
    EXPECT_EQ(download(dev, file).final_status.state, State::kIdle);
    EXPECT_EQ(upload(dev), file);
  }
}

TEST(UsbDfuMode, AbortMidwayLeavesNoImageAndANewDownloadWorks) {
  UsbTestDevice dev;
  dev.enumerate();
  const Bytes file = test_data::model_image_file(pseudo_random(4000, 8));
  for (std::uint16_t b = 0; b < 3; ++b) {
    const Bytes data(file.begin() + 256 * b, file.begin() + 256 * (b + 1));
    ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, b, 256), data).ok());
    ASSERT_EQ(get_status(dev).state, State::kDnBusy);
    dev.usb->service();
    ASSERT_EQ(get_status(dev).state, State::kDnloadIdle);
  }
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kAbort, 0, 0)).ok());
  EXPECT_EQ(get_state(dev), State::kIdle);
  EXPECT_TRUE(upload(dev).empty()) << "an aborted download is no image";
  EXPECT_EQ(download(dev, file).final_status.state, State::kIdle);
  EXPECT_EQ(upload(dev), file);
}

TEST(UsbDfuMode, LengthMismatchesBetweenHeaderAndData) {
  {  // more bytes than the header says
    UsbTestDevice dev;
    dev.enumerate();
    Bytes file = test_data::model_image_file(pseudo_random(300, 9), 0, 200);
    const DownloadTrace t = download(dev, file);
    EXPECT_EQ(t.final_status.status, Status::kErrAddress);
  }
  {  // fewer: the zero-length DNLOAD comes early
    UsbTestDevice dev;
    dev.enumerate();
    const DownloadTrace t = download(dev, test_data::model_image_file(pseudo_random(300, 9), 0, 400));
    EXPECT_EQ(t.final_status.status, Status::kErrNotDone);
  }
  {  // not our envelope
    UsbTestDevice dev;
    dev.enumerate();
    Bytes file = test_data::model_image_file(pseudo_random(300, 9));
    file[0] = 'X';
    EXPECT_EQ(download(dev, file).final_status.status, Status::kErrFile);
  }
}

TEST(UsbDfuMode, BlockNumbersMustCountUp) {
  UsbTestDevice dev;
  dev.enumerate();
  const Bytes file = test_data::model_image_file(pseudo_random(1000, 10));
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 7, 256), Bytes(file.begin(), file.begin() + 256)).ok());
  ASSERT_EQ(get_status(dev).state, State::kDnBusy);
  dev.usb->service();
  ASSERT_EQ(get_status(dev).state, State::kDnloadIdle);
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 9, 256), Bytes(file.begin() + 256, file.begin() + 512)).ok());
  const DfuStatus s = get_status(dev);
  EXPECT_EQ(s.state, State::kError);
  EXPECT_EQ(s.status, Status::kErrAddress);
}

TEST(UsbDfuMode, RequestsInTheWrongStateStallAndEnterDfuError) {
  UsbTestDevice dev;
  dev.enumerate();
  struct Case {
    const char* what;
    SetupPacket setup;
    Bytes out;
  };
  const Case cases[] = {
      {"CLRSTATUS in dfuIDLE", dfu_req(false, dfu::kClrStatus, 0, 0), {}},
      {"zero-length DNLOAD in dfuIDLE", dfu_req(false, dfu::kDnload, 0, 0), {}},
      {"DNLOAD larger than wTransferSize", dfu_req(false, dfu::kDnload, 0, 257), Bytes(257, 0)},
      {"UPLOAD larger than wTransferSize", dfu_req(true, dfu::kUpload, 0, 257), {}},
      {"GETSTATUS wLength 5", dfu_req(true, dfu::kGetStatus, 0, 5), {}},
      {"GETSTATE wLength 2", dfu_req(true, dfu::kGetState, 0, 2), {}},
      {"DETACH in DFU mode", dfu_req(false, dfu::kDetach, 1000, 0), {}},
      {"unknown request 7", dfu_req(false, 7, 0, 0), {}},
      {"ABORT with data", dfu_req(false, dfu::kAbort, 0, 2), Bytes(2, 0)},
  };
  for (const Case& c : cases) {
    EXPECT_TRUE(dev.control(c.setup, c.out).stalled()) << c.what;
    const DfuStatus s = get_status(dev);
    EXPECT_EQ(s.state, State::kError) << c.what;
    EXPECT_EQ(s.status, Status::kErrStalledPacket) << c.what;
    ASSERT_TRUE(dev.control(dfu_req(false, dfu::kClrStatus, 0, 0)).ok()) << c.what;
    EXPECT_EQ(get_state(dev), State::kIdle) << c.what;
  }
  // UPLOAD during a download; GETSTATE while busy.
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 0, 16), test_data::model_image_file({}, 0, 10)).ok());
  ASSERT_EQ(get_status(dev).state, State::kDnBusy);
  EXPECT_TRUE(dev.control(dfu_req(true, dfu::kGetState, 0, 1)).stalled());
  EXPECT_EQ(dev.usb->dfu_mode().state(), State::kError);
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kClrStatus, 0, 0)).ok());
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 0, 16), test_data::model_image_file({}, 0, 10)).ok());
  ASSERT_EQ(get_status(dev).state, State::kDnBusy);
  dev.usb->service();
  ASSERT_EQ(get_status(dev).state, State::kDnloadIdle);
  EXPECT_TRUE(dev.control(dfu_req(true, dfu::kUpload, 0, 64)).stalled());
  EXPECT_EQ(get_status(dev).status, Status::kErrStalledPacket);
  // In dfuERROR only GETSTATUS, GETSTATE and CLRSTATUS are answered.
  EXPECT_EQ(get_state(dev), State::kError);
  EXPECT_TRUE(dev.control(dfu_req(false, dfu::kAbort, 0, 0)).stalled());
}

TEST(UsbDfuMode, TheActiveSlotAlternateIsReadOnly) {
  UsbTestDevice dev;
  dev.enumerate();
  const SetupPacket alt1{request_type(false, RequestKind::kStandard, Recipient::kInterface), request::kSetInterface,
                         1, kDfu, 0};
  ASSERT_TRUE(dev.control(alt1).ok());
  const Bytes file = test_data::model_image_file(pseudo_random(100, 11));
  EXPECT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 0, static_cast<std::uint16_t>(file.size())), file).stalled());
  const DfuStatus s = get_status(dev);
  EXPECT_EQ(s.state, State::kError);
  EXPECT_EQ(s.status, Status::kErrWrite);
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kClrStatus, 0, 0)).ok());
  EXPECT_TRUE(upload(dev).empty()) << "slot A holds nothing yet";
  // Slot A's flash stays erased.
  EXPECT_EQ(slot_bytes(dev, kSlotA, 64), Bytes(64, 0xFF));
}

TEST(UsbDfuMode, PowerCutAtAnyOperationNeverLeavesAHalfImageReadable) {
  // For each operation N of a download over an older image: cut power at N,
  // reboot (power on, new device over the same cells), and read the slot: it
  // must hold either no image or the complete new one (header written last).
  const Bytes old_file = test_data::model_image_file(pseudo_random(700, 12));
  const Bytes new_file = test_data::model_image_file(pseudo_random(900, 13));
  std::uint64_t operations = 0;
  {
    UsbTestDevice dev;
    dev.enumerate();
    ASSERT_EQ(download(dev, old_file).final_status.state, State::kIdle);
    const std::uint64_t before = dev.flash.operation_count();
    ASSERT_EQ(download(dev, new_file).final_status.state, State::kIdle);
    operations = dev.flash.operation_count() - before;
  }
  ASSERT_GE(operations, 5u) << "erase, 4 programs of the payload, the header";
  for (std::uint64_t n = 1; n <= operations; ++n) {
    UsbTestDevice dev;
    dev.enumerate();
    ASSERT_EQ(download(dev, old_file).final_status.state, State::kIdle);
    dev.flash.cut_power_at(dev.flash.operation_count() + n);
    download(dev, new_file);
    EXPECT_FALSE(dev.flash.powered()) << "operation " << n;
    // Reboot: the cells persist.
    Bytes cells(dev.flash.contents().begin(), dev.flash.contents().end());
    UsbTestDevice rebooted;
    std::copy(cells.begin(), cells.end(), rebooted.storage.begin());
    rebooted.enumerate();
    const Bytes got = upload(rebooted);
    EXPECT_TRUE(got.empty() || got == new_file) << "cut at operation " << n << ": " << got.size() << " bytes";
    if (n == operations) {
      EXPECT_TRUE(got.empty()) << "cut while writing the header: no image";
    }
  }
}

}  // namespace
}  // namespace hadynet::usb::testing
