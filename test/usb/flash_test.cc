// The flash seam's simulated NOR flash, the region writer and the STM32F405
// sector table. Exact expectations: bytes, status codes, operation counts.
#include <gtest/gtest.h>

#include <vector>

#include "firmware/flash/flash_region_writer.h"
#include "firmware/flash/simulated_nor_flash.h"
#include "firmware/flash/stm32f405_flash_layout.h"

namespace hadynet::flash {
namespace {

using Bytes = std::vector<std::uint8_t>;

// A small device: sectors of 1, 1, 2 KiB.
constexpr FlashSector kSmall[] = {{0, 1024, 10}, {1024, 1024, 10}, {2048, 2048, 20}};

struct SmallFlash {
  std::vector<std::uint8_t> cells = std::vector<std::uint8_t>(4096);
  SimulatedNorFlash nor{kSmall, cells};
};

TEST(FlashLayout, Stm32f405SectorsAreContiguousMixedSizes) {
  // RM0090: 4 x 16 KiB, 1 x 64 KiB, 7 x 128 KiB from 0x08000000.
  const std::uint32_t expected_kib[12] = {16, 16, 16, 16, 64, 128, 128, 128, 128, 128, 128, 128};
  std::uint32_t offset = 0;
  for (std::size_t i = 0; i < stm32f405::kSectors.size(); ++i) {
    EXPECT_EQ(stm32f405::kSectors[i].offset, offset) << i;
    EXPECT_EQ(stm32f405::kSectors[i].size, expected_kib[i] * 1024) << i;
    offset += stm32f405::kSectors[i].size;
  }
  EXPECT_EQ(offset, 1024u * 1024u);
  EXPECT_TRUE(region_is_sector_aligned(stm32f405::kSectors,
                                       {stm32f405::kModelSlotAOffset, stm32f405::kModelSlotSize}));
  EXPECT_TRUE(region_is_sector_aligned(stm32f405::kSectors,
                                       {stm32f405::kModelSlotBOffset, stm32f405::kModelSlotSize}));
  EXPECT_FALSE(region_is_sector_aligned(stm32f405::kSectors, {0x4000, 0x1000}));
}

TEST(SimulatedNorFlash, ErasedReadsFfAndProgrammingOnlyClearsBits) {
  SmallFlash f;
  Bytes out(8);
  ASSERT_EQ(f.nor.read(100, out), FlashStatus::kOk);
  EXPECT_EQ(out, Bytes(8, 0xFF));
  ASSERT_EQ(f.nor.program(100, Bytes{0x12, 0x34, 0xF0, 0x0F}), FlashStatus::kOk);
  ASSERT_EQ(f.nor.read(100, out), FlashStatus::kOk);
  EXPECT_EQ(out, (Bytes{0x12, 0x34, 0xF0, 0x0F, 0xFF, 0xFF, 0xFF, 0xFF}));
  // Over non-erased bytes: refused, nothing changes (even where it would
  // only clear bits).
  EXPECT_EQ(f.nor.program(100, Bytes{0x02, 0x04, 0x00, 0x00}), FlashStatus::kNotErased);
  ASSERT_EQ(f.nor.read(100, out), FlashStatus::kOk);
  EXPECT_EQ(out[0], 0x12);
  // Erase brings the whole sector back to 0xFF.
  ASSERT_EQ(f.nor.erase_sector(0), FlashStatus::kOk);
  ASSERT_EQ(f.nor.read(100, out), FlashStatus::kOk);
  EXPECT_EQ(out, Bytes(8, 0xFF));
  EXPECT_EQ(f.nor.operation_count(), 2u);
}

TEST(SimulatedNorFlash, RefusesSectorCrossingMisalignedAndOutOfRange) {
  SmallFlash f;
  EXPECT_EQ(f.nor.program(1020, Bytes(8, 0)), FlashStatus::kCrossesSector);
  EXPECT_EQ(f.nor.program(1022, Bytes(4, 0)), FlashStatus::kMisaligned);
  EXPECT_EQ(f.nor.program(1020, Bytes(3, 0)), FlashStatus::kMisaligned);
  EXPECT_EQ(f.nor.program(4096, Bytes(4, 0)), FlashStatus::kOutOfRange);
  EXPECT_EQ(f.nor.erase_sector(3), FlashStatus::kOutOfRange);
  Bytes out(8);
  EXPECT_EQ(f.nor.read(4092, out), FlashStatus::kOutOfRange);
  EXPECT_EQ(f.nor.operation_count(), 0u) << "refused calls are not operations";
  EXPECT_EQ(std::count(f.cells.begin(), f.cells.end(), 0xFF), 4096);
}

TEST(SimulatedNorFlash, PowerCutHalfDoesTheOperationAndStopsEverything) {
  SmallFlash f;
  f.nor.cut_power_at(2);
  ASSERT_EQ(f.nor.program(0, Bytes(8, 0x00)), FlashStatus::kOk);       // operation 1
  EXPECT_EQ(f.nor.program(8, Bytes(8, 0x00)), FlashStatus::kPowerLoss);  // operation 2: half
  EXPECT_EQ((Bytes(f.cells.begin() + 8, f.cells.begin() + 16)), (Bytes{0, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0xFF}));
  Bytes out(4);
  EXPECT_EQ(f.nor.read(0, out), FlashStatus::kPowerLoss);
  EXPECT_EQ(f.nor.erase_sector(0), FlashStatus::kPowerLoss);
  f.nor.power_on();
  EXPECT_EQ(f.nor.read(0, out), FlashStatus::kOk);
  EXPECT_EQ(out, Bytes(4, 0));
  // A cut erase leaves the sector's second half as it was.
  ASSERT_EQ(f.nor.program(1024 - 4, Bytes(4, 0x00)), FlashStatus::kOk);
  f.nor.cut_power_at(f.nor.operation_count() + 1);
  EXPECT_EQ(f.nor.erase_sector(0), FlashStatus::kPowerLoss);
  EXPECT_EQ(f.cells[0], 0xFF);
  EXPECT_EQ(f.cells[1020], 0x00);
}

TEST(SimulatedNorFlash, WriteErrorAtOperationNChangesNothing) {
  SmallFlash f;
  f.nor.fail_write_at(1);
  EXPECT_EQ(f.nor.program(0, Bytes(4, 0)), FlashStatus::kWriteError);
  EXPECT_EQ(f.cells[0], 0xFF);
  EXPECT_EQ(f.nor.program(0, Bytes(4, 0)), FlashStatus::kOk) << "later operations work";
}

TEST(FlashRegionWriter, AppendsOddChunksAcrossSectorsErasingLazily) {
  SmallFlash f;
  // Dirty everything first: the writer must erase before programming.
  for (std::uint32_t i = 0; i < 4096; i += 4) ASSERT_EQ(f.nor.program(i, Bytes(4, 0x55)), FlashStatus::kOk);
  FlashRegionWriter w;
  ASSERT_TRUE(w.begin(f.nor, {1024, 3072}, 16).ok());
  EXPECT_EQ(f.nor.erase_count(), 0u) << "begin erases nothing";
  Bytes data(1500);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 7 + 1);
  std::size_t off = 0;
  for (const std::size_t chunk : {1u, 3u, 250u, 7u, 1000u, 239u}) {
    ASSERT_TRUE(w.append(std::span(data).subspan(off, chunk)).ok());
    off += chunk;
  }
  ASSERT_EQ(off, data.size());
  ASSERT_TRUE(w.finish().ok());
  EXPECT_EQ(w.appended(), 1500u);
  EXPECT_EQ(f.nor.erase_count(), 2u) << "sectors 1 and 2, once each";
  EXPECT_EQ(Bytes(f.cells.begin() + 1024 + 16, f.cells.begin() + 1024 + 16 + 1500), data);
  EXPECT_EQ(f.cells[1024 + 16 + 1500], 0xFF) << "padding of the last unit is 0xFF";
  EXPECT_EQ(Bytes(f.cells.begin() + 1024, f.cells.begin() + 1040), Bytes(16, 0xFF)) << "the header gap";
  EXPECT_EQ(f.cells[1023], 0x55) << "sector 0 untouched";
  ASSERT_TRUE(w.write_at(0, Bytes(16, 0xA5)).ok());
  EXPECT_EQ(Bytes(f.cells.begin() + 1024, f.cells.begin() + 1040), Bytes(16, 0xA5));
  EXPECT_FALSE(w.write_at(8, Bytes(16, 0)).ok()) << "write_at only below the stream's start";
  EXPECT_EQ(w.append(Bytes(3072, 0)).status, FlashStatus::kOutOfRange) << "past the region";
}

TEST(FlashRegionWriter, EstimatesTheEraseItWillTrigger) {
  SmallFlash f;
  FlashRegionWriter w;
  ASSERT_TRUE(w.begin(f.nor, {1024, 3072}, 0).ok());
  // 25 us/byte: 1000 bytes = 25 ms; the first sector's erase 10 ms.
  EXPECT_EQ(w.estimate_append_ms(1000), 10u + 25u);
  ASSERT_TRUE(w.append(Bytes(1000, 0)).ok());
  EXPECT_EQ(w.estimate_append_ms(24), 1u) << "stays in the erased sector";
  EXPECT_EQ(w.estimate_append_ms(25), 20u + 1u) << "reaches sector 2 (20 ms)";
  EXPECT_FALSE(w.begin(f.nor, {1000, 1048}, 0).ok()) << "not sector aligned";
}

}  // namespace
}  // namespace hadynet::flash
