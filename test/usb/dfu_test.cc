// DFU 1.1 through the host backend: the runtime interface's detach, and the
// DFU-mode interface's whole state machine carrying signed model images
// into the model slots through ModelSlots, over the simulated NOR flash with
// the STM32F405's sector table and slots. The host side here behaves like
// dfu-util 0.11 (DNLOAD, then GETSTATUS until dfuDNLOAD-IDLE or dfuERROR,
// sleeping bwPollTimeout = calling service(); zero-length DNLOAD; GETSTATUS
// until dfuIDLE). A reboot is a new device over the same flash cells. Every
// expectation is exact: states, status codes, status texts, poll times, bytes.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "firmware/model_update/slot_layout.h"
#include "firmware/usb/dfu_update_timing.h"
#include "test/usb/test_bytes.h"
#include "usb_test_device.h"

namespace hadynet::usb::testing {
namespace {

namespace mu = model_update;

constexpr std::uint8_t kDfu = composite::kDfuModeInterface;
constexpr std::uint8_t kRuntime = composite::kDfuRuntimeInterface;
constexpr std::uint32_t kHeader = mu::kImageHeaderSize;
using dfu::State;
using dfu::Status;

struct DfuStatus {
  bool ok = false;
  Status status = Status::kOk;
  std::uint32_t poll_ms = 0;
  State state = State::kAppIdle;
  std::uint8_t string_index = 0;
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
  s.string_index = in[5];
  return s;
}

State get_state(UsbTestDevice& dev) {
  Bytes in;
  EXPECT_TRUE(dev.control(dfu_req(true, dfu::kGetState, 0, 1), {}, &in).ok());
  return in.size() == 1 ? static_cast<State>(in[0]) : State::kAppIdle;
}

// The text GETSTATUS's iString names ("" when iString is 0).
std::string status_text(UsbTestDevice& dev) {
  const DfuStatus s = get_status(dev);
  return s.string_index == 0 ? std::string() : dev.string_descriptor(s.string_index);
}

bool clear_status(UsbTestDevice& dev) { return dev.control(dfu_req(false, dfu::kClrStatus, 0, 0)).ok(); }

bool select_alternate(UsbTestDevice& dev, std::uint16_t alt) {
  return dev
      .control({request_type(false, RequestKind::kStandard, Recipient::kInterface), request::kSetInterface, alt,
                kDfu, 0})
      .ok();
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

bool downloaded(UsbTestDevice& dev, const Bytes& file) {
  const DownloadTrace t = download(dev, file);
  return t.final_status.ok && t.final_status.state == State::kIdle && t.final_status.status == Status::kOk;
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

Bytes upload_alt(UsbTestDevice& dev, std::uint16_t alt) {
  EXPECT_TRUE(select_alternate(dev, alt));
  return upload(dev);
}

Bytes cells_of(const UsbTestDevice& dev, const flash::FlashRegion& region) {
  const auto c = dev.flash.contents();
  return Bytes(c.begin() + region.offset, c.begin() + region.offset + region.size);
}

Bytes slot_bytes(const UsbTestDevice& dev, const flash::FlashRegion& slot, std::size_t at, std::size_t n) {
  const auto c = dev.flash.contents();
  return Bytes(c.begin() + slot.offset + static_cast<long>(at), c.begin() + slot.offset + static_cast<long>(at + n));
}

Bytes firmware_image(std::uint32_t sequence, std::uint32_t seed = 1) {
  return make_image(firmware_identity(), ImageSpec{sequence, seed});
}

std::string hash_text(std::uint64_t h) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

// A device running `file` from slot A (downloaded, then booted on a reset).
std::unique_ptr<UsbTestDevice> device_running(const Bytes& file, DeviceSetup setup = {}) {
  UsbTestDevice first(setup);
  first.enumerate();
  EXPECT_TRUE(downloaded(first, file));
  auto dev = first.reboot(setup);
  dev->enumerate();
  EXPECT_EQ(dev->slots->choice().source, mu::ModelSource::kSlotA);
  return dev;
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

TEST(UsbDfuMode, AnImageStreamsIntoAFreeSlotAndUploadsAsTheFileSent) {
  UsbTestDevice dev;
  dev.enumerate();
  // The firmware's own identity: a payload of sizeof(ModelTensors) bytes,
  // which crosses slot A's first 128 KiB sector into the second.
  const Bytes file = firmware_image(1);
  const std::uint32_t payload = firmware_identity().payload_length;
  ASSERT_GT(mu::kSlotPayloadOffset + payload, 128u * 1024u);
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
  // bwPollTimeout: block 0 is the header (the signature check, no flash
  // work); block 1 the first payload bytes: slot A's first 128 KiB sector
  // erased (4000 ms worst case) + 256 bytes at 25 us/byte (7 ms rounded
  // up); plain blocks 7 ms; the block whose bytes reach the second sector
  // erases it; manifestation kDfuManifestMs.
  EXPECT_EQ(t.polls[0], kDfuHeaderCheckMs);
  EXPECT_EQ(kDfuHeaderCheckMs, 250u);
  EXPECT_EQ(t.polls[2], 4000u + 7u);
  EXPECT_EQ(t.polls[4], 7u);
  const std::size_t crossing = 1 + (128 * 1024 - mu::kSlotPayloadOffset) / 256;  // block index
  EXPECT_EQ(t.polls[2 * (crossing - 1)], 7u);
  EXPECT_EQ(t.polls[2 * crossing], 4000u + 7u);
  EXPECT_EQ(t.polls[2 * blocks], kDfuManifestMs);
  EXPECT_EQ(kDfuManifestMs, 2000u);
  EXPECT_EQ(dev.flash.erase_count(), 2u) << "exactly the slot's two sectors";
  // Slot A (the first free slot) holds the header at 0 and the payload at 1024.
  EXPECT_EQ(slot_bytes(dev, kSlotA, 0, kHeader), Bytes(file.begin(), file.begin() + kHeader));
  EXPECT_EQ(slot_bytes(dev, kSlotA, mu::kSlotPayloadOffset, payload), Bytes(file.begin() + kHeader, file.end()));
  // Nothing else was touched: the trial flags and the gap are erased, and so
  // is everything outside the slot.
  const auto c = dev.flash.contents();
  for (std::size_t i = 0; i < c.size(); ++i) {
    const bool header = i >= kSlotA.offset && i < kSlotA.offset + kHeader;
    const bool body = i >= kSlotA.offset + mu::kSlotPayloadOffset && i < kSlotA.offset + mu::kSlotPayloadOffset + payload;
    if (header || body) continue;
    ASSERT_EQ(c[i], 0xFF) << "offset " << i;
  }
  EXPECT_EQ(dev.slots->slot_status(mu::SlotId::kA).state, mu::SlotState::kValid);
  EXPECT_EQ(dev.slots->choice().source, mu::ModelSource::kFactory) << "it runs after the next reset";
  // The result in words, named by iString (status OK).
  const DfuStatus done = get_status(dev);
  EXPECT_EQ(done.status, Status::kOk);
  EXPECT_EQ(done.string_index, composite::string_index::kDfuStatus);
  EXPECT_EQ(status_text(dev), "image sequence 1 written to slot A: the boot rule tries it at the next reset");
  // Upload (alt 0: the slot the last update wrote) returns the file, with
  // the standard and an odd block size; alt 1 (the running model) is the
  // factory model: no slot, 0 bytes.
  EXPECT_EQ(upload(dev), file);
  EXPECT_EQ(get_state(dev), State::kIdle);
  EXPECT_EQ(upload(dev, 100), file);
  EXPECT_TRUE(upload_alt(dev, 1).empty());
}

TEST(UsbDfuMode, AnAcceptedImageBootsAfterAResetAndTheDeviceSaysSo) {
  UsbTestDevice dev;
  dev.enumerate();
  EXPECT_NE(std::string(dev.usb->version()).find("(factory)"), std::string::npos) << dev.usb->version();
  const Bytes first = firmware_image(1, 11);
  ASSERT_TRUE(downloaded(dev, first));
  // Power-on: the boot rule tries slot A (self-test passes) and runs it.
  auto rebooted = dev.reboot();
  rebooted->enumerate();
  EXPECT_EQ(rebooted->slots->choice().source, mu::ModelSource::kSlotA);
  EXPECT_EQ(rebooted->slots->choice().sequence, 1u);
  EXPECT_EQ(rebooted->self_test.runs, 1);
  // The configuration's name: the slot image's model hash, slot and sequence.
  EXPECT_EQ(rebooted->string_descriptor(composite::string_index::kVersion),
            "fw 0.1.0 model " + hash_text(header_of_file(first).model_hash) + " (slot A, sequence 1)");
  EXPECT_EQ(rebooted->usb->running().source, mu::ModelSource::kSlotA);
  // Alt 1 reads the running image; alt 0 the slot the next update writes (B: empty).
  EXPECT_EQ(upload_alt(*rebooted, 1), first);
  EXPECT_TRUE(upload_alt(*rebooted, 0).empty());
  // A newer image goes to slot B, never into the slot in use.
  const Bytes a_before = cells_of(*rebooted, kSlotA);
  const Bytes second = firmware_image(2, 12);
  ASSERT_TRUE(downloaded(*rebooted, second));
  EXPECT_EQ(cells_of(*rebooted, kSlotA), a_before) << "the running slot is untouched";
  EXPECT_EQ(status_text(*rebooted), "image sequence 2 written to slot B: the boot rule tries it at the next reset");
  EXPECT_EQ(upload(*rebooted), second);
  EXPECT_EQ(upload_alt(*rebooted, 1), first) << "A still runs until the reset";
  auto third = rebooted->reboot();
  EXPECT_EQ(third->slots->choice().source, mu::ModelSource::kSlotB);
  EXPECT_EQ(third->slots->choice().sequence, 2u);
  EXPECT_EQ(third->string_descriptor(composite::string_index::kVersion),
            "fw 0.1.0 model " + hash_text(header_of_file(second).model_hash) + " (slot B, sequence 2)");
}

TEST(UsbDfuMode, AnImageFailingItsSelfTestAfterTheResetIsRevertedToTheFactoryModel) {
  UsbTestDevice dev;
  dev.enumerate();
  ASSERT_TRUE(downloaded(dev, firmware_image(1)));
  DeviceSetup failing;
  failing.self_test_passes = false;
  auto rebooted = dev.reboot(failing);
  rebooted->enumerate();
  EXPECT_EQ(rebooted->slots->choice().source, mu::ModelSource::kFactory);
  EXPECT_EQ(rebooted->slots->slot_status(mu::SlotId::kA).state, mu::SlotState::kInvalid);
  EXPECT_EQ(rebooted->string_descriptor(composite::string_index::kVersion),
            "fw 0.1.0 model " + hash_text(Q::kModelHash) + " (factory)");
  EXPECT_TRUE(upload_alt(*rebooted, 1).empty());
}

// One refusal: the bytes sent (whole), the DFU status, the status text.
struct Refusal {
  const char* what;
  Bytes file;
  Status status;
  std::string text;
  bool erases_nothing;  // refused by the header, before anything is erased
};

TEST(UsbDfuMode, EachRefusalHasItsStatusAndTextAndLeavesTheRunningSlotAndBootChoiceAsTheyWere) {
  const Bytes running = firmware_image(3, 30);
  const mu::ModelIdentity id = firmware_identity();
  std::vector<Refusal> cases;
  {
    Bytes f = firmware_image(4);
    f[0] ^= 0xFF;  // magic
    cases.push_back({"not a model image", f, Status::kErrFile, "malformed image header", true});
  }
  cases.push_back({"another contract",
                   make_image(id, {4}, device_key(), [](mu::ModelImageHeader& h) { ++h.contract_version; }),
                   Status::kErrTarget, "model contract version does not match the firmware", true});
  cases.push_back({"another numeric",
                   make_image(id, {4}, device_key(), [](mu::ModelImageHeader& h) { h.numeric = mu::kNumericF32; }),
                   Status::kErrTarget, "numeric (q15/f32) does not match the firmware", true});
  cases.push_back({"another shape", make_image(id, {4}, device_key(), [](mu::ModelImageHeader& h) { h.shape_id ^= 1; }),
                   Status::kErrTarget, "model shape does not match the firmware", true});
  cases.push_back({"another payload length",
                   make_image(id, {4}, device_key(), [](mu::ModelImageHeader& h) { h.payload_length -= 4; }),
                   Status::kErrTarget, "payload length does not match the firmware's model", true});
  cases.push_back({"larger than a slot",
                   make_image(id, {4}, device_key(),
                              [](mu::ModelImageHeader& h) { h.payload_length = kSlotA.size - mu::kSlotPayloadOffset + 1; }),
                   Status::kErrAddress, "image larger than a slot", true});
  cases.push_back({"another key", make_image(id, {4}, stranger_key()), Status::kErrFile, "signed by another key", true});
  {
    Bytes f = firmware_image(4);
    f[mu::header_offset::kDims] ^= 0x01;  // signed information changed after signing
    cases.push_back({"bad signature", f, Status::kErrFile, "signature does not verify", true});
  }
  cases.push_back({"not newer", firmware_image(3, 31), Status::kErrFile,
                   "sequence number not newer than the installed image (downgrade): image 3, newest installed 3 "
                   "(slot A)",
                   true});
  {
    Bytes f = firmware_image(4);
    f[kHeader + 1000] ^= 0x10;  // a payload bit: the stream's SHA-256
    cases.push_back({"payload altered", f, Status::kErrFile, "payload SHA-256 does not match the header", false});
  }
  {
    Bytes f = firmware_image(4);
    f.push_back(0);  // more than the header says
    cases.push_back({"one byte too many", f, Status::kErrAddress, "more payload bytes than the header says", false});
  }
  {
    Bytes f = firmware_image(4);
    f.resize(f.size() - 300);  // the final DNLOAD comes early
    cases.push_back({"truncated", f, Status::kErrNotDone, "payload shorter than the header says", false});
  }
  cases.push_back({"ends inside the header", Bytes(running.begin(), running.begin() + 200), Status::kErrNotDone,
                   "the file ends inside the 256-byte image header", true});

  for (const Refusal& c : cases) {
    SCOPED_TRACE(c.what);
    auto dev = device_running(running);
    const Bytes slot_a = cells_of(*dev, kSlotA);
    const std::uint64_t erases = dev->flash.erase_count();
    const DownloadTrace t = download(*dev, c.file);
    EXPECT_EQ(t.final_status.state, State::kError);
    EXPECT_EQ(t.final_status.status, c.status);
    EXPECT_EQ(t.final_status.string_index, composite::string_index::kDfuStatus);
    EXPECT_EQ(dev->string_descriptor(composite::string_index::kDfuStatus), c.text);
    EXPECT_FALSE(dev->slots->update_in_progress());
    if (c.erases_nothing) {
      EXPECT_EQ(dev->flash.erase_count(), erases) << "refused before anything was erased";
    }
    // The slot in use and the boot choice are as they were, now and after a reset.
    EXPECT_EQ(cells_of(*dev, kSlotA), slot_a);
    EXPECT_EQ(dev->slots->choice().source, mu::ModelSource::kSlotA);
    EXPECT_EQ(dev->slots->choice().sequence, 3u);
    // CLRSTATUS: dfuIDLE, the text cleared; the running model reads back.
    ASSERT_TRUE(clear_status(*dev));
    EXPECT_EQ(get_status(*dev).string_index, 0);
    EXPECT_EQ(upload_alt(*dev, 1), running);
    const auto rebooted = dev->reboot();
    EXPECT_EQ(rebooted->slots->choice().source, mu::ModelSource::kSlotA);
    EXPECT_EQ(rebooted->slots->choice().sequence, 3u);
  }
}

TEST(UsbDfuMode, ADowngradeTheSignerAllowsIsTakenAndRunsAfterTheReset) {
  auto dev = device_running(firmware_image(3, 30));
  const Bytes older = make_image(firmware_identity(), ImageSpec{2, 20, /*downgrade_allowed=*/true});
  ASSERT_TRUE(downloaded(*dev, older));
  EXPECT_EQ(dev->slots->slot_status(mu::SlotId::kA).state, mu::SlotState::kInvalid) << "so the older image wins";
  const auto rebooted = dev->reboot();
  EXPECT_EQ(rebooted->slots->choice().source, mu::ModelSource::kSlotB);
  EXPECT_EQ(rebooted->slots->choice().sequence, 2u);
}

TEST(UsbDfuMode, AnImageFillingTheSlotFitsAndOneByteMoreIsRefusedBeforeAnyErase) {
  DeviceSetup setup;
  setup.identity = firmware_identity();
  setup.identity.payload_length = kSlotA.size - mu::kSlotPayloadOffset;  // a model that fills a slot
  UsbTestDevice dev(setup);
  dev.enumerate();
  const Bytes too_large = make_image(setup.identity, {1}, device_key(), [](mu::ModelImageHeader& h) {
    h.payload_length = kSlotA.size - mu::kSlotPayloadOffset + 1;
  });
  const DownloadTrace t = download(dev, Bytes(too_large.begin(), too_large.begin() + kHeader));
  EXPECT_EQ(t.final_status.state, State::kError);
  EXPECT_EQ(t.final_status.status, Status::kErrAddress);
  EXPECT_EQ(dev.flash.erase_count(), 0u) << "refused before anything was erased";
  ASSERT_TRUE(clear_status(dev));
  const Bytes full = make_image(setup.identity, {1});
  ASSERT_TRUE(downloaded(dev, full));
  EXPECT_EQ(upload(dev), full);
  EXPECT_EQ(dev.reboot(setup)->slots->choice().source, mu::ModelSource::kSlotA);
}

TEST(UsbDfuMode, ARefusedImageLeavesTheLastWrittenImageReadable) {
  UsbTestDevice dev;
  dev.enumerate();
  const Bytes first = firmware_image(1);
  ASSERT_TRUE(downloaded(dev, first));
  const std::uint64_t erases = dev.flash.erase_count();
  const DownloadTrace t = download(dev, make_image(firmware_identity(), {2}, stranger_key()));
  EXPECT_EQ(t.final_status.status, Status::kErrFile);
  EXPECT_EQ(t.blocks_sent, 1u);
  EXPECT_EQ(dev.flash.erase_count(), erases);
  ASSERT_TRUE(clear_status(dev));
  EXPECT_EQ(upload(dev), first);
}

TEST(UsbDfuMode, FlashErrorsBecomeDfuStatusCodesWithTheSlotNamed) {
  {
    UsbTestDevice dev;
    dev.enumerate();
    dev.flash.fail_write_at(1);  // the first operation is the slot's first erase (block 1)
    const DownloadTrace t = download(dev, firmware_image(1));
    EXPECT_EQ(t.final_status.state, State::kError);
    EXPECT_EQ(t.final_status.status, Status::kErrErase);
    EXPECT_EQ(t.blocks_sent, 2u);
    EXPECT_EQ(status_text(dev), "flash error: write error while erasing slot A");
  }
  {
    UsbTestDevice dev;
    dev.enumerate();
    dev.flash.fail_write_at(3);  // erase, program block 1, program block 2 (fails)
    const DownloadTrace t = download(dev, firmware_image(1));
    EXPECT_EQ(t.final_status.state, State::kError);
    EXPECT_EQ(t.final_status.status, Status::kErrWrite);
    EXPECT_EQ(t.blocks_sent, 3u);
    EXPECT_EQ(status_text(dev), "flash error: write error while programming slot A");
    // CLRSTATUS and a new download (the flash works again) succeed.
    ASSERT_TRUE(clear_status(dev));
    EXPECT_EQ(get_state(dev), State::kIdle);
    const Bytes file = firmware_image(1, 7);
    EXPECT_TRUE(downloaded(dev, file));
    EXPECT_EQ(upload(dev), file);
  }
  {
    // The erase of the second sector fails after the bytes below it were
    // programmed (the block that reaches it).
    UsbTestDevice dev;
    dev.enumerate();
    const std::uint64_t first_sector_programs = (128 * 1024 - mu::kSlotPayloadOffset) / 256;
    dev.flash.fail_write_at(1 + first_sector_programs + 1);
    const DownloadTrace t = download(dev, firmware_image(1));
    EXPECT_EQ(t.final_status.status, Status::kErrErase);
    EXPECT_EQ(status_text(dev), "flash error: write error while erasing slot A");
  }
}

TEST(UsbDfuMode, AbortMidwayLeavesNoImageAndANewDownloadWorks) {
  UsbTestDevice dev;
  dev.enumerate();
  const Bytes file = firmware_image(1);
  for (std::uint16_t b = 0; b < 3; ++b) {
    const Bytes data(file.begin() + 256 * b, file.begin() + 256 * (b + 1));
    ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, b, 256), data).ok());
    ASSERT_EQ(get_status(dev).state, State::kDnBusy);
    dev.usb->service();
    ASSERT_EQ(get_status(dev).state, State::kDnloadIdle);
  }
  ASSERT_TRUE(dev.slots->update_in_progress());
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kAbort, 0, 0)).ok());
  EXPECT_EQ(get_state(dev), State::kIdle);
  EXPECT_FALSE(dev.slots->update_in_progress()) << "ABORT ends the update";
  EXPECT_TRUE(upload(dev).empty()) << "an aborted download is no image";
  EXPECT_EQ(dev.slots->slot_status(mu::SlotId::kA).state, mu::SlotState::kEmpty);
  EXPECT_TRUE(downloaded(dev, file));
  EXPECT_EQ(upload(dev), file);
}

TEST(UsbDfuMode, ABusResetOrAnotherAlternateMidwayEndsTheUpdate) {
  UsbTestDevice dev;
  dev.enumerate();
  const Bytes file = firmware_image(1);
  const auto start = [&] {
    for (std::uint16_t b = 0; b < 2; ++b) {
      ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, b, 256),
                              Bytes(file.begin() + 256 * b, file.begin() + 256 * (b + 1)))
                      .ok());
      get_status(dev);
      dev.usb->service();
      ASSERT_EQ(get_status(dev).state, State::kDnloadIdle);
    }
    ASSERT_TRUE(dev.slots->update_in_progress());
  };
  start();
  ASSERT_TRUE(select_alternate(dev, 0));
  EXPECT_FALSE(dev.slots->update_in_progress());
  EXPECT_EQ(get_state(dev), State::kIdle);
  start();
  dev.enumerate();
  EXPECT_FALSE(dev.slots->update_in_progress());
  EXPECT_TRUE(downloaded(dev, file));
}

TEST(UsbDfuMode, BlockNumbersMustCountUp) {
  UsbTestDevice dev;
  dev.enumerate();
  const Bytes file = firmware_image(1);
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 7, 256), Bytes(file.begin(), file.begin() + 256)).ok());
  ASSERT_EQ(get_status(dev).state, State::kDnBusy);
  dev.usb->service();
  ASSERT_EQ(get_status(dev).state, State::kDnloadIdle);
  ASSERT_TRUE(dev.slots->update_in_progress());
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 9, 256), Bytes(file.begin() + 256, file.begin() + 512)).ok());
  const DfuStatus s = get_status(dev);
  EXPECT_EQ(s.state, State::kError);
  EXPECT_EQ(s.status, Status::kErrAddress);
  EXPECT_EQ(dev.string_descriptor(s.string_index), "DNLOAD block number out of sequence");
  EXPECT_FALSE(dev.slots->update_in_progress()) << "the error ends the update";
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
    EXPECT_EQ(dev.string_descriptor(s.string_index), "request not allowed in this DFU state (2)") << c.what;
    ASSERT_TRUE(clear_status(dev)) << c.what;
    EXPECT_EQ(get_state(dev), State::kIdle) << c.what;
  }
  // UPLOAD during a download; GETSTATE while busy (each ends the update).
  const Bytes image = firmware_image(1);
  const Bytes head(image.begin(), image.begin() + 16);
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 0, 16), head).ok());
  ASSERT_EQ(get_status(dev).state, State::kDnBusy);
  EXPECT_TRUE(dev.control(dfu_req(true, dfu::kGetState, 0, 1)).stalled());
  EXPECT_EQ(dev.usb->dfu_mode().state(), State::kError);
  ASSERT_TRUE(clear_status(dev));
  ASSERT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 0, 16), head).ok());
  ASSERT_EQ(get_status(dev).state, State::kDnBusy);
  dev.usb->service();
  ASSERT_EQ(get_status(dev).state, State::kDnloadIdle);
  EXPECT_TRUE(dev.control(dfu_req(true, dfu::kUpload, 0, 64)).stalled());
  EXPECT_EQ(get_status(dev).status, Status::kErrStalledPacket);
  // In dfuERROR only GETSTATUS, GETSTATE and CLRSTATUS are answered.
  EXPECT_EQ(get_state(dev), State::kError);
  EXPECT_TRUE(dev.control(dfu_req(false, dfu::kAbort, 0, 0)).stalled());
}

TEST(UsbDfuMode, TheRunningModelAlternateIsReadOnly) {
  UsbTestDevice dev;
  dev.enumerate();
  ASSERT_TRUE(select_alternate(dev, 1));
  const Bytes file = firmware_image(1);
  EXPECT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 0, 256), Bytes(file.begin(), file.begin() + 256)).stalled());
  const DfuStatus s = get_status(dev);
  EXPECT_EQ(s.state, State::kError);
  EXPECT_EQ(s.status, Status::kErrWrite);
  EXPECT_EQ(dev.string_descriptor(s.string_index),
            "alternate 1 (the running model) is read only: send images to alternate 0");
  ASSERT_TRUE(clear_status(dev));
  EXPECT_TRUE(upload(dev).empty()) << "the factory model runs: no slot in use";
  // The slots' flash stays erased.
  EXPECT_EQ(slot_bytes(dev, kSlotA, 0, 1024), Bytes(1024, 0xFF));
  EXPECT_EQ(slot_bytes(dev, kSlotB, 0, 1024), Bytes(1024, 0xFF));
}

TEST(UsbDfuMode, WithoutModelSlotsDownloadsAndUploadsAreRefused) {
  DeviceSetup setup;
  setup.model_slots = false;
  UsbTestDevice dev(setup);
  dev.enumerate();
  EXPECT_EQ(dev.string_descriptor(composite::string_index::kVersion),
            "fw 0.1.0 model " + hash_text(Q::kModelHash) + " (factory)");
  const Bytes file = firmware_image(1);
  EXPECT_TRUE(dev.control(dfu_req(false, dfu::kDnload, 0, 256), Bytes(file.begin(), file.begin() + 256)).stalled());
  DfuStatus s = get_status(dev);
  EXPECT_EQ(s.state, State::kError);
  EXPECT_EQ(s.status, Status::kErrTarget);
  EXPECT_EQ(dev.string_descriptor(s.string_index), "this device has no model slots: it takes no model images");
  ASSERT_TRUE(clear_status(dev));
  EXPECT_TRUE(dev.control(dfu_req(true, dfu::kUpload, 0, 256)).stalled());
  s = get_status(dev);
  EXPECT_EQ(s.status, Status::kErrTarget);
  EXPECT_EQ(dev.flash.operation_count(), 0u);
}

TEST(UsbDfuMode, BeforeTheBootRuleRanUpdatesAreRefused) {
  DeviceSetup setup;
  setup.boot = false;
  UsbTestDevice dev(setup);
  dev.enumerate();
  const DownloadTrace t = download(dev, firmware_image(1));
  EXPECT_EQ(t.final_status.status, Status::kErrTarget);
  EXPECT_EQ(t.blocks_sent, 1u);
  EXPECT_EQ(dev.string_descriptor(composite::string_index::kDfuStatus), "no boot decision yet");
}

TEST(UsbDfuMode, APowerCutAtAnyFlashOperationLeavesTheOldOrTheNewModelRunning) {
  // A small model (3000 payload bytes), so every operation can be cut. The
  // old image (sequence 1) runs from slot A; the new one (sequence 2) goes
  // to B. For each operation N of that download: power cut at N, reset
  // (new device over the same cells, boot rule), then the device runs
  // either the old image with B empty, or the new one with A intact; the
  // running model and the other slot read back as whole files, never half.
  DeviceSetup setup;
  setup.identity = small_identity();
  const Bytes old_file = make_image(setup.identity, {1, 12});
  const Bytes new_file = make_image(setup.identity, {2, 13});
  std::uint64_t operations = 0;
  {
    auto dev = device_running(old_file, setup);
    const std::uint64_t before = dev->flash.operation_count();
    ASSERT_TRUE(downloaded(*dev, new_file));
    operations = dev->flash.operation_count() - before;
  }
  ASSERT_GE(operations, 5u) << "erase, the payload's programs, the header";
  for (std::uint64_t n = 1; n <= operations; ++n) {
    SCOPED_TRACE("power cut at operation " + std::to_string(n));
    auto dev = device_running(old_file, setup);
    dev->flash.cut_power_at(dev->flash.operation_count() + n);
    download(*dev, new_file);
    EXPECT_FALSE(dev->flash.powered());
    auto rebooted = dev->reboot(setup);
    rebooted->enumerate();
    const mu::BootChoice& choice = rebooted->slots->choice();
    const Bytes running = upload_alt(*rebooted, 1);
    const Bytes other = upload_alt(*rebooted, 0);
    if (choice.source == mu::ModelSource::kSlotA) {
      EXPECT_EQ(choice.sequence, 1u);
      EXPECT_EQ(running, old_file);
      EXPECT_TRUE(other.empty()) << other.size() << " bytes";
    } else {
      EXPECT_EQ(choice.source, mu::ModelSource::kSlotB);
      EXPECT_EQ(choice.sequence, 2u);
      EXPECT_EQ(running, new_file);
      EXPECT_EQ(other, old_file);
    }
    if (n == operations) {
      EXPECT_EQ(choice.source, mu::ModelSource::kSlotA) << "cut while writing the header: no new image";
    }
  }
}

}  // namespace
}  // namespace hadynet::usb::testing
