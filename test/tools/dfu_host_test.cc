// Host-side DFU pieces that need no device: the DfuSe memory-layout string
// and the firmware image loader. Expectations are exact (addresses, sizes,
// bytes).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "tools/usb/dfuse_memory_layout.h"
#include "tools/usb/firmware_image.h"

namespace hadynet::tools::usb {
namespace {

namespace fs = std::filesystem;

TEST(DfuseMemoryLayout, TheF405RomStringGivesItsTwelveSectors) {
  std::string error;
  const auto layout = parse_dfuse_memory_layout("@Internal Flash  /0x08000000/04*016Kg,01*064Kg,07*128Kg", error);
  ASSERT_TRUE(layout) << error;
  EXPECT_EQ(layout->name, "Internal Flash");
  ASSERT_EQ(layout->sectors.size(), 12u);
  EXPECT_EQ(layout->sectors[0].address, 0x08000000u);
  EXPECT_EQ(layout->sectors[0].size, 16u * 1024);
  EXPECT_EQ(layout->sectors[4].address, 0x08010000u);
  EXPECT_EQ(layout->sectors[4].size, 64u * 1024);
  EXPECT_EQ(layout->sectors[5].address, 0x08020000u);
  EXPECT_EQ(layout->sectors[11].address, 0x080E0000u);
  EXPECT_EQ(layout->sectors[11].size, 128u * 1024);
  EXPECT_TRUE(layout->sectors[3].readable && layout->sectors[3].erasable && layout->sectors[3].writable);
  EXPECT_EQ(layout->sector_at(0x0801FFFF), &layout->sectors[4]);
  EXPECT_EQ(layout->sector_at(0x08100000), nullptr);
}

TEST(DfuseMemoryLayout, ReadOnlyTypesAndSeveralBlocks) {
  std::string error;
  const auto layout = parse_dfuse_memory_layout("@Option Bytes  /0x1FFFC000/01*016 e/0x1FFEC000/01*016 a", error);
  ASSERT_TRUE(layout) << error;
  ASSERT_EQ(layout->sectors.size(), 2u);
  EXPECT_EQ(layout->sectors[0].size, 16u);
  EXPECT_TRUE(layout->sectors[0].readable);
  EXPECT_FALSE(layout->sectors[0].erasable);
  EXPECT_TRUE(layout->sectors[0].writable);  // 'e' = readable + writable
  EXPECT_EQ(layout->sectors[1].address, 0x1FFEC000u);
  EXPECT_FALSE(layout->sectors[1].writable);
}

TEST(DfuseMemoryLayout, MalformedStringsNameThePosition) {
  std::string error;
  EXPECT_FALSE(parse_dfuse_memory_layout("Internal Flash/0x08000000/04*016Kg", error));
  EXPECT_NE(error.find("character 1"), std::string::npos) << error;
  EXPECT_FALSE(parse_dfuse_memory_layout("@Flash/0x08000000/04*016Kz", error));
  EXPECT_NE(error.find("type letter"), std::string::npos) << error;
  EXPECT_FALSE(parse_dfuse_memory_layout("@Flash/0x08000000/04016Kg", error));
  EXPECT_NE(error.find("'*'"), std::string::npos) << error;
  EXPECT_FALSE(parse_dfuse_memory_layout("@Flash/0xFFFFF000/02*004Kg", error));
  EXPECT_NE(error.find("4 GiB"), std::string::npos) << error;
}

fs::path write_file(const std::string& name, const std::vector<std::uint8_t>& bytes) {
  const fs::path path = fs::temp_directory_path() / ("hadynet_dfu_host_test_" + name);
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                               static_cast<std::streamsize>(bytes.size()));
  return path;
}

void put16(std::vector<std::uint8_t>& b, std::size_t at, std::uint16_t v) {
  b[at] = static_cast<std::uint8_t>(v);
  b[at + 1] = static_cast<std::uint8_t>(v >> 8);
}
void put32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// An ELF32 ARM executable with PT_LOAD segments {load address, bytes} and
// one PT_LOAD without file bytes (.bss).
std::vector<std::uint8_t> elf(const std::vector<std::pair<std::uint32_t, std::vector<std::uint8_t>>>& segments,
                              std::uint16_t machine = 40) {
  const std::size_t phoff = 52, phnum = segments.size() + 1;
  std::vector<std::uint8_t> b(phoff + 32 * phnum, 0);
  b[0] = 0x7F, b[1] = 'E', b[2] = 'L', b[3] = 'F', b[4] = 1, b[5] = 1, b[6] = 1;
  put16(b, 16, 2), put16(b, 18, machine), put32(b, 20, 1), put32(b, 28, phoff);
  put16(b, 40, 52), put16(b, 42, 32), put16(b, 44, static_cast<std::uint16_t>(phnum));
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const std::size_t h = phoff + 32 * i;
    put32(b, h, 1);
    put32(b, h + 4, static_cast<std::uint32_t>(b.size()));
    put32(b, h + 8, 0x20000000);  // p_vaddr differs from the load address (like .data)
    put32(b, h + 12, segments[i].first);
    put32(b, h + 16, static_cast<std::uint32_t>(segments[i].second.size()));
    put32(b, h + 20, static_cast<std::uint32_t>(segments[i].second.size()));
    b.insert(b.end(), segments[i].second.begin(), segments[i].second.end());
  }
  const std::size_t bss = phoff + 32 * segments.size();
  put32(b, bss, 1), put32(b, bss + 12, 0x20001000), put32(b, bss + 20, 4096);  // no file bytes
  return b;
}

TEST(FirmwareImage, ElfLoadSegmentsAtTheirLoadAddressesWithTheGapErased) {
  const auto path = write_file("two.elf", elf({{0x08000000, {1, 2, 3, 4}}, {0x08000008, {9, 8}}}));
  const FirmwareImage image = load_firmware_image(path);
  EXPECT_EQ(image.address, 0x08000000u);
  EXPECT_EQ(image.bytes, (std::vector<std::uint8_t>{1, 2, 3, 4, 0xFF, 0xFF, 0xFF, 0xFF, 9, 8}));
}

TEST(FirmwareImage, ABinaryGoesToTheFlashOrigin) {
  const auto path = write_file("raw.bin", {5, 6, 7});
  const FirmwareImage image = load_firmware_image(path);
  EXPECT_EQ(image.address, kStm32FlashOrigin);
  EXPECT_EQ(image.bytes, (std::vector<std::uint8_t>{5, 6, 7}));
}

TEST(FirmwareImage, RefusesWhatIsNotAnImage) {
  const auto expect_error = [](const fs::path& p, const std::string& words) {
    try {
      load_firmware_image(p);
      ADD_FAILURE() << p << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << "names the file: " << e.what();
    }
  };
  expect_error(write_file("empty.bin", {}), "empty");
  expect_error(write_file("x86.elf", elf({{0x08000000, {1}}}, 62)), "not an ARM executable");
  expect_error(write_file("nothing.elf", elf({})), "no loadable bytes");
  expect_error(fs::temp_directory_path() / "hadynet_dfu_host_test_missing.elf", "cannot open");
}

}  // namespace
}  // namespace hadynet::tools::usb
