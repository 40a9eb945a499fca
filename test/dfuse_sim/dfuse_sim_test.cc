// The simulated STM32 ROM DfuSe bootloader driven at the device level: the
// host side of the FakeController (bus reset, SETUP, IN/OUT through whole
// control transfers), like dfu-util would. Expected values come from AN3156,
// the F405 reference manual and datasheet, written out here, not from the
// simulator's own tables. Every comparison is exact (simulated time, bytes).
#include <gtest/gtest.h>

#include "test/dfuse_sim/sim_host.h"

namespace hadynet::usb::host_testing {
namespace {

using dfu::State;
using dfu::Status;

struct StatusReply {
  bool ok = false;
  Status status = Status::kOk;
  std::uint32_t poll_ms = 0;
  State state = State::kIdle;
};

StatusReply get_status(host::FakeController& c) {
  const Bytes in = control_in(c, dfu_request(true, dfu::kGetStatus, 0, 6));
  StatusReply r;
  if (in.size() != 6) return r;
  r.ok = true;
  r.status = static_cast<Status>(in[0]);
  r.poll_ms = in[1] | (in[2] << 8) | (in[3] << 16);
  r.state = static_cast<State>(in[4]);
  return r;
}

bool dnload(host::FakeController& c, std::uint16_t block, const Bytes& data) {
  return c.control(dfu_request(false, dfu::kDnload, block, static_cast<std::uint16_t>(data.size())), data, {}).ok();
}

Bytes command(std::uint8_t code, std::uint32_t address) {
  return {code, static_cast<std::uint8_t>(address), static_cast<std::uint8_t>(address >> 8),
          static_cast<std::uint8_t>(address >> 16), static_cast<std::uint8_t>(address >> 24)};
}

class RomBootloaderTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(enumerate(sim.controller())); }

  // A DfuSe command or a data block, then the two GETSTATUS: dfuDNBUSY with
  // `poll_ms`, then `final_state` / `final_status`.
  void run(std::uint16_t block, const Bytes& data, std::uint32_t poll_ms, State final_state = State::kDnloadIdle,
           Status final_status = Status::kOk) {
    ASSERT_TRUE(dnload(c(), block, data));
    const StatusReply busy = get_status(c());
    ASSERT_TRUE(busy.ok);
    EXPECT_EQ(busy.state, State::kDnBusy);
    EXPECT_EQ(busy.status, Status::kOk);
    EXPECT_EQ(busy.poll_ms, poll_ms);
    const StatusReply done = get_status(c());
    ASSERT_TRUE(done.ok);
    EXPECT_EQ(done.state, final_state);
    EXPECT_EQ(done.status, final_status);
  }

  Bytes flash_bytes(std::uint32_t address, std::size_t n) {
    const auto cells = sim.flash().cells();
    return Bytes(cells.begin() + (address - 0x08000000), cells.begin() + (address - 0x08000000) + n);
  }

  host::FakeController& c() { return sim.controller(); }
  Stm32RomBootloader sim;
};

TEST_F(RomBootloaderTest, DeviceDescriptorIsTheRoms) {
  const Bytes d = control_in(c(), get_descriptor(descriptor::kDevice, 0, 18));
  // USB 2.00, class 0, EP0 64, 0483:df11, bcdDevice 0x2200, strings 1/2/3, 1 configuration.
  const Bytes expected = {18, 1, 0x00, 0x02, 0, 0, 0, 64, 0x83, 0x04, 0x11, 0xDF, 0x00, 0x22, 1, 2, 3, 1};
  EXPECT_EQ(d, expected);
  EXPECT_EQ(read_string(c(), 1), "STMicroelectronics");
  EXPECT_EQ(read_string(c(), 2), "STM32  BOOTLOADER");
  EXPECT_EQ(read_string(c(), 3).size(), 12u);
}

TEST_F(RomBootloaderTest, ConfigurationHasFourAlternatesAndTheFunctionalDescriptor) {
  const Bytes d = control_in(c(), get_descriptor(descriptor::kConfiguration, 0, 255));
  ASSERT_EQ(d.size(), 9u + 4 * 9 + 9);  // configuration + 4 interfaces + DFU functional
  EXPECT_EQ(d[2] | (d[3] << 8), static_cast<int>(d.size()));  // wTotalLength
  EXPECT_EQ(d[4], 1);  // bNumInterfaces
  const char* const expected_alt[] = {
      "@Internal Flash  /0x08000000/04*016Kg,01*064Kg,07*128Kg",
      "@Option Bytes  /0x1FFFC000/01*016 e",
      "@OTP Memory /0x1FFF7800/01*512 e,01*016 e",
      "@Device Feature/0xFFFF0000/01*004 e",
  };
  for (std::uint8_t alt = 0; alt < 4; ++alt) {
    const std::size_t at = 9 + 9 * alt;
    EXPECT_EQ(d[at + 1], descriptor::kInterface);
    EXPECT_EQ(d[at + 2], 0) << "bInterfaceNumber";
    EXPECT_EQ(d[at + 3], alt) << "bAlternateSetting";
    EXPECT_EQ(d[at + 4], 0) << "bNumEndpoints";
    EXPECT_EQ(d[at + 5], 0xFE);
    EXPECT_EQ(d[at + 6], 0x01);
    EXPECT_EQ(d[at + 7], 0x02) << "DFU mode";
    EXPECT_EQ(read_string(c(), d[at + 8]), expected_alt[alt]);
  }
  // bLength 9, DFU functional 0x21, bmAttributes 0x0B, wDetachTimeOut 255,
  // wTransferSize 2048, bcdDFU 0x011A.
  const Bytes functional(d.begin() + 45, d.end());
  EXPECT_EQ(functional, (Bytes{9, 0x21, 0x0B, 0xFF, 0x00, 0x00, 0x08, 0x1A, 0x01}));
}

TEST_F(RomBootloaderTest, UploadBlockZeroListsTheCommands) {
  const Bytes list = control_in(c(), dfu_request(true, dfu::kUpload, 0, 2048));
  EXPECT_EQ(list, (Bytes{0x00, 0x21, 0x41, 0x92}));
  EXPECT_EQ(get_status(c()).state, State::kUploadIdle);
}

TEST_F(RomBootloaderTest, SetAddressAndEraseAnswerBusyThenIdle) {
  run(0, command(0x21, 0x08004000), 1);
  EXPECT_EQ(sim.dfu().address_pointer(), 0x08004000u);
  // Sector 1 (16 KiB): the datasheet's worst-case 16 KiB erase, 800 ms.
  run(0, command(0x41, 0x08004000), 800);
  // Sector 5 (128 KiB): 4000 ms; sector 4 (64 KiB): 2400 ms.
  run(0, command(0x41, 0x08020000), 4000);
  run(0, command(0x41, 0x08010000), 2400);
  EXPECT_EQ(sim.flash().erase_count(), 3u);
}

// The poll-time knob scales what GETSTATUS reports, rounded up to whole ms
// (1 % of 800 ms = 8; of the 1 ms set-address = 0.01 -> 1; of a 2048-byte
// write's 52 ms = 0.52 -> 1), 0 % reports 0; the datasheet sum it keeps
// is unscaled (1 + 800 + 52 + 1 + 800 + 52 ms for the two rounds).
TEST_F(RomBootloaderTest, PollTimeoutPercentScalesTheReportedWait) {
  sim.set_poll_timeout_percent(1);
  run(0, command(0x21, 0x08004000), 1);
  run(0, command(0x41, 0x08004000), 8);
  run(2, pseudo_random(2048, 3), 1);
  sim.set_poll_timeout_percent(0);
  run(0, command(0x21, 0x08004000), 0);
  run(0, command(0x41, 0x08004000), 0);
  run(2, pseudo_random(2048, 3), 0);
  EXPECT_EQ(sim.dfu().datasheet_poll_ms(), 2u * (1 + 800 + 52));
  EXPECT_EQ(flash_bytes(0x08004000, 2048), pseudo_random(2048, 3));
}

TEST_F(RomBootloaderTest, EraseOfOneSectorLeavesItsNeighboursIntact) {
  const Bytes fill(0x30000, 0x5A);  // sectors 0..4 and half of 5
  sim.flash().fill(0x08000000, fill);
  run(0, command(0x41, 0x08009abc), 800);  // any address inside sector 2 (0x08008000, 16 KiB)
  EXPECT_EQ(flash_bytes(0x08008000, 0x4000), Bytes(0x4000, 0xFF));
  EXPECT_EQ(flash_bytes(0x08000000, 0x8000), Bytes(0x8000, 0x5A));        // sectors 0, 1
  EXPECT_EQ(flash_bytes(0x0800C000, 0x30000 - 0xC000), Bytes(0x30000 - 0xC000, 0x5A));  // 3 onwards
  EXPECT_EQ(sim.flash().erases_of(2), 1u);
}

TEST_F(RomBootloaderTest, WriteThenReadBack) {
  const Bytes data = pseudo_random(2048 + 2048 + 100, 7);
  run(0, command(0x21, 0x08010000), 1);
  // 25 us/byte worst case (datasheet, x32): 2048 B -> 51.2 ms, rounded up to 52; 100 B -> 3 ms.
  run(2, Bytes(data.begin(), data.begin() + 2048), 52);
  run(3, Bytes(data.begin() + 2048, data.begin() + 4096), 52);
  run(4, Bytes(data.begin() + 4096, data.end()), 3);
  EXPECT_EQ(flash_bytes(0x08010000, data.size()), data);
  EXPECT_EQ(sim.bridge().transfers(), 2u) << "the two 2048-byte blocks went through the bridge";

  ASSERT_TRUE(c().control(dfu_request(false, dfu::kAbort, 0, 0), {}, {}).ok());
  Bytes back;
  for (std::uint16_t block = 2; block <= 4; ++block) {
    const std::uint16_t want = block < 4 ? 2048 : 100;
    const Bytes part = control_in(c(), dfu_request(true, dfu::kUpload, block, want));
    ASSERT_EQ(part.size(), want);
    back.insert(back.end(), part.begin(), part.end());
  }
  EXPECT_EQ(back, data);
}

TEST_F(RomBootloaderTest, ProgrammingOnlyClearsBits) {
  run(0, command(0x21, 0x08000000), 1);
  run(2, Bytes(4, 0x0F), 1);  // 4 B x 25 us = 0.1 ms, rounded up to 1
  // 0xF0 over 0x0F needs 0 -> 1 bits: the cells keep the AND (0x00), the ROM's check fails.
  run(2, Bytes(4, 0xF0), 1, State::kError, Status::kErrVerify);
  EXPECT_EQ(flash_bytes(0x08000000, 4), Bytes(4, 0x00));
  ASSERT_TRUE(c().control(dfu_request(false, dfu::kClrStatus, 0, 0), {}, {}).ok());
  EXPECT_EQ(get_status(c()).state, State::kIdle);
}

TEST_F(RomBootloaderTest, BadAddressesAreErrors) {
  run(0, command(0x21, 0x08100000), 1, State::kError, Status::kErrTarget);  // 1 MiB past the start
  EXPECT_EQ(sim.dfu().address_pointer(), 0x08000000u) << "the pointer is unchanged";
  ASSERT_TRUE(c().control(dfu_request(false, dfu::kClrStatus, 0, 0), {}, {}).ok());
  run(0, command(0x41, 0x20000000), 1, State::kError, Status::kErrTarget);  // RAM: no sector
  ASSERT_TRUE(c().control(dfu_request(false, dfu::kClrStatus, 0, 0), {}, {}).ok());
  // The last 16 bytes of flash, then block 3 = 2048 bytes past them: outside.
  run(0, command(0x21, 0x080FFFF0), 1);
  run(3, Bytes(16, 0), 1, State::kError, Status::kErrAddress);
  EXPECT_EQ(sim.flash().erase_count(), 0u);
}

TEST_F(RomBootloaderTest, RequestsNotAllowedInTheStateStallIntoError) {
  // DETACH is a runtime request: STALL, dfuERROR errSTALLEDPKT.
  EXPECT_TRUE(c().control(dfu_request(false, dfu::kDetach, 255, 0), {}, {}).stalled());
  StatusReply s = get_status(c());
  EXPECT_EQ(s.state, State::kError);
  EXPECT_EQ(s.status, Status::kErrStalledPacket);
  // GETSTATE answers in dfuERROR; CLRSTATUS leaves it.
  EXPECT_EQ(control_in(c(), dfu_request(true, dfu::kGetState, 0, 1)), Bytes{10});
  ASSERT_TRUE(c().control(dfu_request(false, dfu::kClrStatus, 0, 0), {}, {}).ok());
  // An unknown class request: STALL only, the state stays dfuIDLE.
  EXPECT_TRUE(c().control(dfu_request(true, 0x07, 0, 4), {}, {}).stalled());
  EXPECT_EQ(control_in(c(), dfu_request(true, dfu::kGetState, 0, 1)), Bytes{2});
}

TEST_F(RomBootloaderTest, LeaveManifestsThenDropsOffTheBus) {
  run(0, command(0x21, 0x08000000), 1);
  ASSERT_TRUE(dnload(c(), 0, {}));
  EXPECT_TRUE(sim.attached()) << "still there until the GETSTATUS";
  const StatusReply s = get_status(c());
  EXPECT_EQ(s.state, State::kManifest);
  EXPECT_EQ(s.status, Status::kOk);
  EXPECT_FALSE(sim.attached());
  EXPECT_FALSE(c().connected()) << "the pull-up is off";
  ASSERT_TRUE(sim.jump_address().has_value());
  EXPECT_EQ(*sim.jump_address(), 0x08000000u);
}

TEST_F(RomBootloaderTest, InjectedStallAndStatusError) {
  {
    DfuseFaults f;
    f.error_at_block = 3;
    f.error_status = Status::kErrWrite;
    f.stall_request = dfu::kGetState;
    f.stall_occurrence = 2;
    sim.set_faults(f);
  }
  run(0, command(0x21, 0x08000000), 1);
  run(2, Bytes(8, 0x11), 1);
  run(3, Bytes(8, 0x22), 1, State::kError, Status::kErrWrite);
  EXPECT_EQ(flash_bytes(0x08000000, 16), (Bytes{0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0xFF, 0xFF, 0xFF,
                                                 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}));
  ASSERT_TRUE(c().control(dfu_request(false, dfu::kClrStatus, 0, 0), {}, {}).ok());
  EXPECT_TRUE(c().control(dfu_request(true, dfu::kGetState, 0, 1), {}, {}).ok());
  EXPECT_TRUE(c().control(dfu_request(true, dfu::kGetState, 0, 1), {}, {}).stalled());  // the 2nd
  EXPECT_TRUE(c().control(dfu_request(true, dfu::kGetState, 0, 1), {}, {}).ok());
}

TEST_F(RomBootloaderTest, VanishesAfterTheChosenBlock) {
  {
    DfuseFaults f;
    f.vanish_after_block = 2;
    sim.set_faults(f);
  }
  run(0, command(0x21, 0x08000000), 1);
  ASSERT_TRUE(dnload(c(), 2, Bytes(8, 0x00)));
  EXPECT_EQ(get_status(c()).state, State::kDnBusy);
  EXPECT_FALSE(sim.attached());
  EXPECT_FALSE(sim.jump_address().has_value()) << "a vanish is not a leave";
  EXPECT_EQ(flash_bytes(0x08000000, 8), Bytes(8, 0x00)) << "block 2 was written first";
}

}  // namespace
}  // namespace hadynet::usb::host_testing
