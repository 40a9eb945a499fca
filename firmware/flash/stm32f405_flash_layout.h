// The STM32F405's 1 MiB flash as a sector table (RM0090 §3.3, table 5;
// erase times from the datasheet's table "Flash memory programming", x32
// parallelism, 2.7..3.6 V: 16 KiB 800 ms, 64 KiB 2400 ms, 128 KiB 4000 ms
// worst case; word programming 100 µs worst case = 25 µs/byte).
//
// Model slots A and B (firmware/model_update/: signed model images, boot
// rule, updates; the layout inside a slot is firmware/model_update/
// slot_layout.h): sectors 8..9 and 10..11, 256 KiB each, two 128 KiB
// sectors per slot; the firmware image keeps sectors 0..7 (512 KiB; today's
// image is about 253 KB with the compiled-in model, docs/model-update.md).
#ifndef HADYNET_FIRMWARE_FLASH_STM32F405_FLASH_LAYOUT_H_
#define HADYNET_FIRMWARE_FLASH_STM32F405_FLASH_LAYOUT_H_

#include <array>
#include <cstdint>

#include "firmware/flash/flash_device.h"

namespace hadynet::flash::stm32f405 {

inline constexpr std::uint32_t kFlashBase = 0x08000000u;  // offset 0 of the FlashDevice
inline constexpr std::uint32_t kProgramAlignment = 4;     // x32 programming
inline constexpr std::uint32_t kProgramMaxUsPerByte = 25;

inline constexpr std::array<FlashSector, 12> kSectors = {{
    {0x00000, 16 * 1024, 800},   {0x04000, 16 * 1024, 800},   {0x08000, 16 * 1024, 800},
    {0x0C000, 16 * 1024, 800},   {0x10000, 64 * 1024, 2400},  {0x20000, 128 * 1024, 4000},
    {0x40000, 128 * 1024, 4000}, {0x60000, 128 * 1024, 4000}, {0x80000, 128 * 1024, 4000},
    {0xA0000, 128 * 1024, 4000}, {0xC0000, 128 * 1024, 4000}, {0xE0000, 128 * 1024, 4000},
}};
inline constexpr std::uint32_t kFlashSize = 0x100000;  // 1 MiB
static_assert(kSectors.back().offset + kSectors.back().size == kFlashSize);

// The model slots (offset, size in bytes).
inline constexpr std::uint32_t kModelSlotAOffset = 0x80000;
inline constexpr std::uint32_t kModelSlotBOffset = 0xC0000;
inline constexpr std::uint32_t kModelSlotSize = 256 * 1024;

}  // namespace hadynet::flash::stm32f405

#endif  // HADYNET_FIRMWARE_FLASH_STM32F405_FLASH_LAYOUT_H_
