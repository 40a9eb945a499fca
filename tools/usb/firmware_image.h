// A firmware image to write into the MCU's flash: the bytes and the address
// they go to. From a raw binary (`objcopy -O binary`, as the build writes
// next to each .elf: it starts at the flash origin) or from the ELF itself
// (its PT_LOAD segments' load addresses and file bytes, gaps between them
// filled with 0xFF, the erased value).
#ifndef HADYNET_TOOLS_USB_FIRMWARE_IMAGE_H_
#define HADYNET_TOOLS_USB_FIRMWARE_IMAGE_H_

#include <cstdint>
#include <filesystem>
#include <vector>

namespace hadynet::tools::usb {

inline constexpr std::uint32_t kStm32FlashOrigin = 0x08000000;

struct FirmwareImage {
  std::uint32_t address = 0;       // where bytes[0] goes
  std::vector<std::uint8_t> bytes;
};

// .elf (by its magic) or anything else as a raw binary at `bin_address`.
// Throws std::runtime_error naming the file and what is wrong (unreadable,
// empty, not a 32-bit little-endian ARM executable, no loadable bytes,
// larger than 16 MiB).
FirmwareImage load_firmware_image(const std::filesystem::path& path, std::uint32_t bin_address = kStm32FlashOrigin);

}  // namespace hadynet::tools::usb

#endif  // HADYNET_TOOLS_USB_FIRMWARE_IMAGE_H_
