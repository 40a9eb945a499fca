// The memory layout a DfuSe device names in its alternate setting's string
// (ST UM0424 / AN3156), e.g. the STM32F405's ROM bootloader:
//   "@Internal Flash  /0x08000000/04*016Kg,01*064Kg,07*128Kg"
// = a name, a start address, then groups "<count>*<size><unit><type>"
// (unit ' ' bytes, 'K' KiB, 'M' MiB; type letters a..g: bit 0 readable,
// bit 1 erasable, bit 2 writable; 'g' = all three). Several address blocks
// may follow, separated by '/'.
#ifndef HADYNET_TOOLS_USB_DFUSE_MEMORY_LAYOUT_H_
#define HADYNET_TOOLS_USB_DFUSE_MEMORY_LAYOUT_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hadynet::tools::usb {

struct DfuseSector {
  std::uint32_t address = 0;
  std::uint32_t size = 0;  // bytes
  bool readable = false;
  bool erasable = false;
  bool writable = false;
};

struct DfuseMemoryLayout {
  std::string name;                 // "Internal Flash"
  std::vector<DfuseSector> sectors;  // in address order

  // The sector holding `address`, or nullptr.
  const DfuseSector* sector_at(std::uint32_t address) const;
};

// Parses the string; nullopt (and `error` set, naming the position) if it
// is not a DfuSe memory description.
std::optional<DfuseMemoryLayout> parse_dfuse_memory_layout(const std::string& text, std::string& error);

}  // namespace hadynet::tools::usb

#endif  // HADYNET_TOOLS_USB_DFUSE_MEMORY_LAYOUT_H_
