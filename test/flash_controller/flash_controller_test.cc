// The STM32F405 flash driver (boards/stm32f405/flash_controller.h) against
// the fake flash interface: register sequences, preconditions, error flags,
// bounded waits, read-back verification, and equivalence with
// SimulatedNorFlash (the seam's reference backend) over a whole sector.
#include "boards/stm32f405/flash_controller.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "firmware/flash/simulated_nor_flash.h"
#include "test/flash_controller/fake_flash_interface.h"

namespace hadynet::board::stm32 {
namespace {

using flash::FlashStatus;
using test::FakeFlashInterface;
namespace layout = flash::stm32f405;

using FakeFlashController = BasicFlashController<FakeFlashInterface::Hook>;

constexpr std::uint32_t kCoreClockHz = 168000000;
constexpr std::uint32_t kSector8 = 0x80000;
constexpr std::uint32_t kSector9 = 0xA0000;
constexpr std::uint32_t kSector10 = 0xC0000;
constexpr std::uint32_t kSector9Size = 128 * 1024;

std::vector<std::uint8_t> pattern(std::size_t size, std::uint32_t seed) {
  std::vector<std::uint8_t> bytes(size);
  std::uint32_t x = seed;
  for (std::uint8_t& b : bytes) {
    x = x * 1664525u + 1013904223u;
    b = static_cast<std::uint8_t>(x >> 24);
  }
  return bytes;
}

class FlashControllerTest : public ::testing::Test {
 protected:
  FakeFlashController make(std::uint32_t core_clock_hz = kCoreClockHz,
                           FirmwareSectors firmware = FirmwareSectors::kRefuse) {
    return FakeFlashController(fake_.registers, fake_.window.data(), core_clock_hz, firmware, fake_.hook());
  }
  std::uint32_t last_cr_write() const { return fake_.writes_to(FlashRegister::kCr).back(); }

  FakeFlashInterface fake_;
};

TEST_F(FlashControllerTest, PollBudgetsFollowTheDocumentedFormula) {
  // ceil(2 * max_us * f / (1e6 * 4)), at least 1.
  EXPECT_EQ(poll_budget(4000000, 168000000), 336000000u);
  EXPECT_EQ(poll_budget(100, 168000000), 8400u);
  EXPECT_EQ(poll_budget(100, 8000), 1u);
  EXPECT_EQ(poll_budget(0, 168000000), 1u);
  FakeFlashController controller = make();
  EXPECT_EQ(controller.erase_poll_budget(9), 336000000u);
  EXPECT_EQ(controller.erase_poll_budget(0), 67200000u);  // 16 KiB, 800 ms
  EXPECT_EQ(controller.word_poll_budget(), 8400u);
}

TEST_F(FlashControllerTest, UnlocksWithBothKeysInOrderAndRelocksAfterEachOperation) {
  FakeFlashController controller = make();
  ASSERT_EQ(controller.erase_sector(9), FlashStatus::kOk);
  const std::vector<FakeFlashInterface::RegisterWrite>& writes = fake_.register_writes();
  ASSERT_GE(writes.size(), 2u);
  EXPECT_EQ(writes[0].reg, FlashRegister::kKeyr);
  EXPECT_EQ(writes[0].value, kFlashKey1);
  EXPECT_EQ(writes[1].reg, FlashRegister::kKeyr);
  EXPECT_EQ(writes[1].value, kFlashKey2);
  EXPECT_EQ(fake_.writes_to(FlashRegister::kKeyr).size(), 2u);
  EXPECT_EQ(last_cr_write(), kFlashCrLock);
  EXPECT_TRUE(fake_.locked());
  EXPECT_FALSE(fake_.key_sequence_broken());
  EXPECT_EQ(fake_.ignored_cr_writes(), 0u);

  fake_.clear_logs();
  const std::vector<std::uint8_t> data = pattern(64, 1);
  ASSERT_EQ(controller.program(kSector9, data), FlashStatus::kOk);
  EXPECT_EQ(fake_.writes_to(FlashRegister::kKeyr), (std::vector<std::uint32_t>{kFlashKey1, kFlashKey2}));
  EXPECT_EQ(last_cr_write(), kFlashCrLock);
  EXPECT_TRUE(fake_.locked());
  EXPECT_EQ(fake_.cr_writes_while_busy(), 0u);
}

TEST_F(FlashControllerTest, EraseOfSector9WritesSerSnbPsizeThenStrt) {
  const std::vector<std::uint8_t> old = pattern(kSector9Size, 2);
  fake_.preset(kSector9, old);
  fake_.preset(kSector8 + kSector9Size - 16, pattern(16, 3));  // neighbours must survive
  fake_.preset(kSector10, pattern(16, 4));
  FakeFlashController controller = make();
  ASSERT_EQ(controller.erase_sector(9), FlashStatus::kOk);

  const std::uint32_t command = kFlashCrSer | (9u << kFlashCrSnb) | kFlashCrPsizeX32;
  EXPECT_EQ(fake_.writes_to(FlashRegister::kCr), (std::vector<std::uint32_t>{command, command | kFlashCrStrt,
                                                                             kFlashCrLock}));
  EXPECT_EQ(fake_.window_writes().size(), 0u);
  for (std::uint32_t i = 0; i < kSector9Size; ++i) ASSERT_EQ(fake_.cells()[kSector9 + i], 0xFF) << i;
  const std::vector<std::uint8_t> before = pattern(16, 3), after = pattern(16, 4);
  for (std::uint32_t i = 0; i < 16; ++i) {
    EXPECT_EQ(fake_.cells()[kSector8 + kSector9Size - 16 + i], before[i]);
    EXPECT_EQ(fake_.cells()[kSector10 + i], after[i]);
  }
}

TEST_F(FlashControllerTest, ProgramOfEightBytesStoresTwoWordsWithPgSet) {
  FakeFlashController controller = make();
  const std::array<std::uint8_t, 8> data = {0x01, 0x02, 0x03, 0x04, 0xA5, 0x5A, 0x00, 0xFE};
  ASSERT_EQ(controller.program(kSector9 + 16, data), FlashStatus::kOk);
  const std::vector<FakeFlashInterface::WindowWrite>& words = fake_.window_writes();
  ASSERT_EQ(words.size(), 2u);
  EXPECT_EQ(words[0].offset, kSector9 + 16);
  EXPECT_EQ(words[0].value, 0x04030201u);  // little-endian, as the flash reads back
  EXPECT_EQ(words[1].offset, kSector9 + 20);
  EXPECT_EQ(words[1].value, 0xFE005AA5u);
  for (const FakeFlashInterface::WindowWrite& w : words) EXPECT_EQ(w.cr, kFlashCrPg | kFlashCrPsizeX32);
  EXPECT_EQ(fake_.writes_to(FlashRegister::kCr),
            (std::vector<std::uint32_t>{kFlashCrPg | kFlashCrPsizeX32, kFlashCrLock}));
  std::array<std::uint8_t, 8> back{};
  ASSERT_EQ(controller.read(kSector9 + 16, back), FlashStatus::kOk);
  EXPECT_EQ(back, data);
}

TEST_F(FlashControllerTest, StaleErrorFlagsAreClearedBeforeTheOperationStarts) {
  fake_.set_status_flags(kFlashSrPgserr | kFlashSrPgperr);  // as some F4s come out of reset
  FakeFlashController controller = make();
  ASSERT_EQ(controller.program(kSector9, pattern(8, 5)), FlashStatus::kOk);
  const std::vector<FakeFlashInterface::RegisterWrite>& writes = fake_.register_writes();
  ASSERT_GE(writes.size(), 4u);
  EXPECT_EQ(writes[2].reg, FlashRegister::kSr);  // after the keys, before any CR write
  EXPECT_EQ(writes[2].value, kFlashSrErrors | kFlashSrEop);
  EXPECT_EQ(writes[3].reg, FlashRegister::kCr);
  EXPECT_EQ(fake_.status() & kFlashSrErrors, 0u);
}

struct RefusedCase {
  const char* name;
  bool erase;
  std::size_t sector;   // erase
  std::uint32_t offset;  // program
  std::size_t size;
  bool preset_target;  // program over programmed bytes
  FlashStatus expected;
};

class FlashControllerRefusalTest : public FlashControllerTest, public ::testing::WithParamInterface<RefusedCase> {};

TEST_P(FlashControllerRefusalTest, IsRefusedWithoutTouchingTheController) {
  const RefusedCase& c = GetParam();
  if (c.preset_target) fake_.preset(c.offset + 4, pattern(4, 6));
  fake_.clear_logs();
  FakeFlashController controller = make();
  const std::vector<std::uint8_t> data = pattern(c.size, 7);
  const FlashStatus status = c.erase ? controller.erase_sector(c.sector) : controller.program(c.offset, data);
  EXPECT_EQ(status, c.expected);
  EXPECT_TRUE(fake_.register_writes().empty());
  EXPECT_TRUE(fake_.window_writes().empty());
  EXPECT_EQ(fake_.status_reads(), 0u);
  EXPECT_TRUE(fake_.locked());
}

INSTANTIATE_TEST_SUITE_P(
    Preconditions, FlashControllerRefusalTest,
    ::testing::Values(RefusedCase{"EraseSectorPastTheEnd", true, 12, 0, 0, false, FlashStatus::kOutOfRange},
                      RefusedCase{"ProgramPastTheEnd", false, 0, 0x100000, 4, false, FlashStatus::kOutOfRange},
                      RefusedCase{"ProgramOverTheEnd", false, 0, 0xFFFFC, 8, false, FlashStatus::kOutOfRange},
                      RefusedCase{"MisalignedOffset", false, 0, kSector9 + 2, 4, false, FlashStatus::kMisaligned},
                      RefusedCase{"MisalignedSize", false, 0, kSector9, 6, false, FlashStatus::kMisaligned},
                      RefusedCase{"CrossesSector", false, 0, kSector10 - 4, 8, false, FlashStatus::kCrossesSector},
                      RefusedCase{"NotErased", false, 0, kSector9 + 64, 16, true, FlashStatus::kNotErased},
                      RefusedCase{"EraseFirmwareSector0", true, 0, 0, 0, false, FlashStatus::kOutOfRange},
                      RefusedCase{"EraseFirmwareSector7", true, 7, 0, 0, false, FlashStatus::kOutOfRange},
                      RefusedCase{"ProgramFirmwareSector0", false, 0, 0x0, 8, false, FlashStatus::kOutOfRange},
                      RefusedCase{"ProgramFirmwareSector7", false, 0, 0x7FFF0, 16, false, FlashStatus::kOutOfRange}),
    [](const ::testing::TestParamInfo<RefusedCase>& param_info) { return std::string(param_info.param.name); });

TEST_F(FlashControllerTest, FirmwareSectorsAreWritableOnlyWithTheExplicitFlag) {
  FakeFlashController controller = make(kCoreClockHz, FirmwareSectors::kAllow);
  EXPECT_EQ(controller.erase_sector(0), FlashStatus::kOk);
  EXPECT_EQ(fake_.writes_to(FlashRegister::kCr)[1], kFlashCrSer | kFlashCrPsizeX32 | kFlashCrStrt);  // SNB = 0
  EXPECT_EQ(controller.program(0x7FFF0, pattern(16, 8)), FlashStatus::kOk);
  EXPECT_TRUE(fake_.locked());
}

class FlashControllerErrorFlagTest : public FlashControllerTest, public ::testing::WithParamInterface<std::uint32_t> {};

TEST_P(FlashControllerErrorFlagTest, EraseErrorIsReportedClearedAndRelocked) {
  fake_.preset(kSector9, pattern(64, 9));
  FakeFlashController controller = make();
  fake_.fail_next_operation(GetParam());
  EXPECT_EQ(controller.erase_sector(9), FlashStatus::kWriteError);
  EXPECT_EQ(fake_.status() & kFlashSrErrors, 0u);
  EXPECT_EQ(fake_.writes_to(FlashRegister::kSr).back(), GetParam());
  EXPECT_EQ(last_cr_write(), kFlashCrLock);
  EXPECT_TRUE(fake_.locked());
  // The next operation works.
  EXPECT_EQ(controller.erase_sector(9), FlashStatus::kOk);
}

TEST_P(FlashControllerErrorFlagTest, ProgramErrorStopsAtTheFailingWordClearedAndRelocked) {
  FakeFlashController controller = make();
  fake_.fail_next_operation(GetParam());
  EXPECT_EQ(controller.program(kSector9, pattern(32, 10)), FlashStatus::kWriteError);
  EXPECT_EQ(fake_.window_writes().size(), 1u);
  EXPECT_EQ(fake_.status() & kFlashSrErrors, 0u);
  EXPECT_EQ(last_cr_write(), kFlashCrLock);
  EXPECT_TRUE(fake_.locked());
}

INSTANTIATE_TEST_SUITE_P(Flags, FlashControllerErrorFlagTest,
                         ::testing::Values(kFlashSrPgserr, kFlashSrWrperr, kFlashSrPgperr, kFlashSrPgaerr,
                                           kFlashSrOperr, kFlashSrPgserr | kFlashSrWrperr));

// A small core clock gives small budgets: 40 kHz -> 80000 polls for a
// 128 KiB sector, 2 polls per word.
constexpr std::uint32_t kSlowClockHz = 40000;

TEST_F(FlashControllerTest, EraseThatNeverFinishesTimesOutAfterTheBudget) {
  FakeFlashController controller = make(kSlowClockHz);
  const std::uint32_t budget = controller.erase_poll_budget(9);
  ASSERT_EQ(budget, 80000u);
  fake_.hang_next_operation();
  EXPECT_EQ(controller.erase_sector(9), FlashStatus::kWriteError);
  // `budget` polls in the wait, then end_operation's read of the flags.
  EXPECT_EQ(fake_.busy_status_reads(), budget + 1u);
  EXPECT_EQ(last_cr_write(), kFlashCrLock);  // on the MCU this write waits for BSY
  EXPECT_TRUE(fake_.locked());
}

TEST_F(FlashControllerTest, WordThatNeverFinishesTimesOutAfterTheBudget) {
  FakeFlashController controller = make(kSlowClockHz);
  ASSERT_EQ(controller.word_poll_budget(), 2u);
  fake_.hang_next_operation();
  EXPECT_EQ(controller.program(kSector9, pattern(16, 11)), FlashStatus::kWriteError);
  EXPECT_EQ(fake_.window_writes().size(), 1u);
  EXPECT_EQ(fake_.busy_status_reads(), 3u);
  EXPECT_TRUE(fake_.locked());
}

TEST_F(FlashControllerTest, BusyControllerIsNotTouched) {
  FakeFlashController controller = make(kSlowClockHz);
  fake_.set_busy_now();
  EXPECT_EQ(controller.program(kSector9, pattern(8, 12)), FlashStatus::kWriteError);
  EXPECT_EQ(fake_.busy_status_reads(), controller.word_poll_budget());
  EXPECT_TRUE(fake_.register_writes().empty());
  EXPECT_TRUE(fake_.window_writes().empty());
}

TEST_F(FlashControllerTest, SlowButFinishingOperationsSucceedWithinTheBudget) {
  fake_.set_busy_polls(79999, 2);
  FakeFlashController controller = make(kSlowClockHz);
  EXPECT_EQ(controller.erase_sector(9), FlashStatus::kOk);
  EXPECT_EQ(controller.program(kSector9, pattern(64, 13)), FlashStatus::kOk);
}

TEST_F(FlashControllerTest, ReadBackCatchesAWordThatWasNotProgrammed) {
  FakeFlashController controller = make();
  fake_.keep_word_unprogrammed(kSector9 + 8);
  EXPECT_EQ(controller.program(kSector9, pattern(16, 14)), FlashStatus::kWriteError);
  EXPECT_EQ(fake_.window_writes().size(), 4u);  // no flag: every word was stored
  EXPECT_TRUE(fake_.locked());
}

TEST_F(FlashControllerTest, BlankCheckCatchesAWordThatWasNotErased) {
  fake_.preset(kSector9, pattern(kSector9Size, 15));
  FakeFlashController controller = make();
  fake_.keep_word_unerased(kSector9 + kSector9Size - 4);
  EXPECT_EQ(controller.erase_sector(9), FlashStatus::kWriteError);
  EXPECT_TRUE(fake_.locked());
}

TEST_F(FlashControllerTest, DataCacheIsResetAfterAnOperationAndRestored) {
  const std::uint32_t acr = 5u | kFlashAcrPrefetch | kFlashAcrICache | kFlashAcrDCache;  // as clock_tree.cc
  fake_.reset(acr);
  FakeFlashController controller = make();
  ASSERT_EQ(controller.erase_sector(9), FlashStatus::kOk);
  const std::uint32_t off = acr & ~kFlashAcrDCache;
  EXPECT_EQ(fake_.writes_to(FlashRegister::kAcr),
            (std::vector<std::uint32_t>{off, off | kFlashAcrDCacheReset, off, acr}));
  EXPECT_EQ(fake_.registers.acr, acr);
}

// The same operations on the driver (against the fake) and on
// SimulatedNorFlash give the same statuses and the same bytes.
TEST_F(FlashControllerTest, SectorRoundTripEqualsSimulatedNorFlash) {
  std::vector<std::uint8_t> storage(layout::kFlashSize);
  flash::SimulatedNorFlash reference(layout::kSectors, storage);
  FakeFlashController controller = make();
  const std::vector<std::uint8_t> old = pattern(kSector9Size, 16);
  const std::vector<std::uint8_t> image = pattern(kSector9Size, 17);
  // Statuses of: a program, one over it (refused), the erase, the image in
  // chunks of mixed sizes, a program across a sector end and a misaligned
  // one (refused).
  const auto run = [&](flash::FlashDevice& device) {
    const std::uint32_t chunk_sizes[] = {4, 8, 12, 256, 1020, 4096, 60};
    std::vector<FlashStatus> statuses;
    statuses.push_back(device.program(kSector9, std::span(old).first(4096)));
    statuses.push_back(device.program(kSector9, std::span(image).first(8)));
    statuses.push_back(device.erase_sector(9));
    std::uint32_t at = 0;
    for (std::size_t i = 0; at < kSector9Size; ++i) {
      const std::uint32_t n = std::min(chunk_sizes[i % std::size(chunk_sizes)], kSector9Size - at);
      statuses.push_back(device.program(kSector9 + at, std::span(image).subspan(at, n)));
      at += n;
    }
    statuses.push_back(device.program(kSector10 - 4, std::span(image).first(8)));
    statuses.push_back(device.program(kSector9 + 3, std::span(image).first(4)));
    return statuses;
  };
  const std::vector<FlashStatus> driver_statuses = run(controller);
  const std::vector<FlashStatus> reference_statuses = run(reference);
  EXPECT_EQ(driver_statuses, reference_statuses);
  ASSERT_GT(driver_statuses.size(), 5u);
  EXPECT_EQ(driver_statuses[1], FlashStatus::kNotErased);
  EXPECT_EQ(driver_statuses[driver_statuses.size() - 2], FlashStatus::kCrossesSector);
  EXPECT_EQ(driver_statuses.back(), FlashStatus::kMisaligned);
  for (std::size_t i = 2; i + 2 < driver_statuses.size(); ++i) EXPECT_EQ(driver_statuses[i], FlashStatus::kOk) << i;

  std::vector<std::uint8_t> from_driver(kSector9Size + 32), from_reference(kSector9Size + 32);
  ASSERT_EQ(controller.read(kSector9 - 16, from_driver), FlashStatus::kOk);
  ASSERT_EQ(reference.read(kSector9 - 16, from_reference), FlashStatus::kOk);
  EXPECT_EQ(from_driver, from_reference);
  EXPECT_TRUE(std::equal(image.begin(), image.end(), from_driver.begin() + 16));
  std::array<std::uint8_t, 7> odd_driver{}, odd_reference{};  // unaligned read
  ASSERT_EQ(controller.read(kSector9 + 1001, odd_driver), FlashStatus::kOk);
  ASSERT_EQ(reference.read(kSector9 + 1001, odd_reference), FlashStatus::kOk);
  EXPECT_EQ(odd_driver, odd_reference);
  EXPECT_EQ(controller.read(layout::kFlashSize - 2, odd_driver), reference.read(layout::kFlashSize - 2, odd_reference));
  EXPECT_TRUE(std::equal(storage.begin(), storage.end(), fake_.cells().begin()));
  EXPECT_TRUE(fake_.locked());
  EXPECT_FALSE(fake_.key_sequence_broken());
}

}  // namespace
}  // namespace hadynet::board::stm32
