#include "tools/usb/dfuse_memory_layout.h"

#include <cctype>
#include <cstdlib>

namespace hadynet::tools::usb {

const DfuseSector* DfuseMemoryLayout::sector_at(std::uint32_t address) const {
  for (const DfuseSector& s : sectors) {
    if (address >= s.address && address - s.address < s.size) return &s;
  }
  return nullptr;
}

namespace {

bool parse_number(const std::string& text, std::size_t& at, int base, std::uint64_t& value) {
  std::size_t end = at;
  while (end < text.size() && std::isxdigit(static_cast<unsigned char>(text[end])) &&
         (base == 16 || std::isdigit(static_cast<unsigned char>(text[end])))) {
    ++end;
  }
  if (end == at || end - at > 10) return false;
  value = std::strtoull(text.substr(at, end - at).c_str(), nullptr, base);
  at = end;
  return true;
}

}  // namespace

std::optional<DfuseMemoryLayout> parse_dfuse_memory_layout(const std::string& text, std::string& error) {
  const auto fail = [&](std::size_t at, const std::string& what) -> std::optional<DfuseMemoryLayout> {
    error = "DfuSe memory layout '" + text + "', character " + std::to_string(at + 1) + ": " + what;
    return std::nullopt;
  };
  if (text.empty() || text[0] != '@') return fail(0, "expected '@' and a name");
  std::size_t at = text.find('/');
  if (at == std::string::npos) return fail(text.size(), "expected '/' and a start address");
  DfuseMemoryLayout layout;
  layout.name = text.substr(1, at - 1);
  while (!layout.name.empty() && layout.name.back() == ' ') layout.name.pop_back();
  while (at < text.size()) {
    ++at;  // the '/'
    if (text.compare(at, 2, "0x") != 0 && text.compare(at, 2, "0X") != 0) return fail(at, "expected 0x<address>");
    at += 2;
    std::uint64_t address = 0;
    if (!parse_number(text, at, 16, address) || address > 0xFFFFFFFFull) return fail(at, "bad address");
    if (at >= text.size() || text[at] != '/') return fail(at, "expected '/' after the address");
    ++at;
    for (;;) {
      std::uint64_t count = 0, size = 0;
      if (!parse_number(text, at, 10, count) || count == 0) return fail(at, "expected a sector count");
      if (at >= text.size() || text[at] != '*') return fail(at, "expected '*'");
      ++at;
      if (!parse_number(text, at, 10, size) || size == 0) return fail(at, "expected a sector size");
      if (at >= text.size()) return fail(at, "expected a unit and a type");
      const char unit = text[at++];
      if (unit == 'K') {
        size *= 1024;
      } else if (unit == 'M') {
        size *= 1024 * 1024;
      } else if (unit != ' ' && unit != 'B') {
        return fail(at - 1, "unit must be ' ', 'B', 'K' or 'M'");
      }
      if (at >= text.size() || text[at] < 'a' || text[at] > 'g') return fail(at, "expected a type letter a..g");
      const int type = text[at++] - 'a' + 1;
      for (std::uint64_t i = 0; i < count; ++i) {
        if (address + size > 0x100000000ull) return fail(at, "sectors run past 4 GiB");
        layout.sectors.push_back({static_cast<std::uint32_t>(address), static_cast<std::uint32_t>(size),
                                  (type & 1) != 0, (type & 2) != 0, (type & 4) != 0});
        address += size;
      }
      if (at < text.size() && text[at] == ',') {
        ++at;
        continue;
      }
      break;
    }
    if (at < text.size() && text[at] != '/') return fail(at, "expected ',' or '/'");
  }
  if (layout.sectors.empty()) return fail(text.size(), "no sectors");
  return layout;
}

}  // namespace hadynet::tools::usb
