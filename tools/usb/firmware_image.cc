#include "tools/usb/firmware_image.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

namespace hadynet::tools::usb {
namespace {

constexpr std::size_t kMaxImageBytes = 16u << 20;  // loadable bytes: far beyond any MCU flash this tool writes
constexpr std::size_t kMaxFileBytes = 256u << 20;  // an ELF with debug information may be large
constexpr std::uint16_t kElfMachineArm = 40;       // EM_ARM
constexpr std::uint32_t kPtLoad = 1;

std::uint16_t u16(const std::vector<std::uint8_t>& b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}
std::uint32_t u32(const std::vector<std::uint8_t>& b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) | (static_cast<std::uint32_t>(b[at + 1]) << 8) |
         (static_cast<std::uint32_t>(b[at + 2]) << 16) | (static_cast<std::uint32_t>(b[at + 3]) << 24);
}

FirmwareImage from_elf(const std::vector<std::uint8_t>& file, const std::string& name) {
  const auto fail = [&](const std::string& what) { return std::runtime_error(name + ": " + what); };
  // ELF32 header (e_ident[EI_CLASS] = 1, EI_DATA = 1 little-endian).
  if (file.size() < 52 || file[4] != 1 || file[5] != 1) throw fail("not a 32-bit little-endian ELF file");
  if (u16(file, 18) != kElfMachineArm) throw fail("not an ARM executable (e_machine " + std::to_string(u16(file, 18)) + ")");
  const std::uint32_t phoff = u32(file, 28);
  const std::uint16_t phentsize = u16(file, 42), phnum = u16(file, 44);
  if (phentsize < 32 || phoff > file.size() || static_cast<std::uint64_t>(phnum) * phentsize > file.size() - phoff) {
    throw fail("program headers out of the file");
  }
  struct Segment {
    std::uint32_t address, offset, size;
  };
  std::vector<Segment> segments;
  for (std::uint16_t i = 0; i < phnum; ++i) {
    const std::size_t h = phoff + static_cast<std::size_t>(i) * phentsize;
    if (u32(file, h) != kPtLoad) continue;
    const Segment s{u32(file, h + 12) /* p_paddr: the load address */, u32(file, h + 4), u32(file, h + 16)};
    if (s.size == 0) continue;  // .bss and the stack: nothing to write
    if (s.offset > file.size() || s.size > file.size() - s.offset) throw fail("a segment lies outside the file");
    segments.push_back(s);
  }
  if (segments.empty()) throw fail("no loadable bytes (no PT_LOAD segment with file data)");
  std::sort(segments.begin(), segments.end(), [](const Segment& a, const Segment& b) { return a.address < b.address; });
  const std::uint64_t start = segments.front().address;
  std::uint64_t end = 0;
  for (const Segment& s : segments) end = std::max<std::uint64_t>(end, static_cast<std::uint64_t>(s.address) + s.size);
  if (end - start > kMaxImageBytes) throw fail("loadable bytes span more than 16 MiB (segments far apart?)");
  FirmwareImage image;
  image.address = static_cast<std::uint32_t>(start);
  image.bytes.assign(static_cast<std::size_t>(end - start), 0xFF);
  for (const Segment& s : segments) {
    std::copy_n(file.begin() + s.offset, s.size, image.bytes.begin() + (s.address - start));
  }
  return image;
}

}  // namespace

FirmwareImage load_firmware_image(const std::filesystem::path& path, std::uint32_t bin_address) {
  const std::string name = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(name + ": cannot open (" + std::strerror(errno) + ")");
  std::vector<std::uint8_t> file;
  char chunk[65536];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    file.insert(file.end(), chunk, chunk + in.gcount());
    if (file.size() > kMaxFileBytes) throw std::runtime_error(name + ": larger than 256 MiB: not a firmware image");
  }
  if (file.empty()) throw std::runtime_error(name + ": empty file");
  if (file.size() >= 4 && file[0] == 0x7F && file[1] == 'E' && file[2] == 'L' && file[3] == 'F') {
    return from_elf(file, name);
  }
  if (file.size() > kMaxImageBytes) throw std::runtime_error(name + ": larger than 16 MiB: not a firmware image");
  return FirmwareImage{bin_address, std::move(file)};
}

}  // namespace hadynet::tools::usb
