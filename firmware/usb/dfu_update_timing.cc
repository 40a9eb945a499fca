#include "firmware/usb/dfu_update_timing.h"

#include "firmware/model_update/slot_layout.h"

namespace hadynet::usb {

namespace {

// The device offsets a stream into `slot` has programmed after accepting
// `accepted` payload bytes: [start, end).
std::uint32_t programmed_end(const flash::FlashDevice& flash, const flash::FlashRegion& slot,
                             std::uint64_t accepted) noexcept {
  const std::uint32_t unit = flash.program_alignment() > 0 ? flash.program_alignment() : 1;
  return slot.offset + model_update::kSlotPayloadOffset + static_cast<std::uint32_t>(accepted - accepted % unit);
}

// The end of what the stream has erased when it has programmed up to
// `programmed` (the slot's start: nothing erased yet).
std::uint32_t erased_end(const flash::FlashDevice& flash, const flash::FlashRegion& slot,
                         std::uint32_t programmed) noexcept {
  const std::uint32_t start = slot.offset + model_update::kSlotPayloadOffset;
  if (programmed <= start) return slot.offset;
  const std::span<const flash::FlashSector> sectors = flash.sectors();
  const std::size_t i = flash::sector_of(sectors, programmed - 1);
  return i == sectors.size() ? programmed : sectors[i].offset + sectors[i].size;
}

}  // namespace

std::uint32_t payload_append_ms(const flash::FlashDevice& flash, const flash::FlashRegion& slot,
                                std::uint32_t written, std::size_t bytes) noexcept {
  const std::span<const flash::FlashSector> sectors = flash.sectors();
  const std::uint32_t from = programmed_end(flash, slot, written);
  const std::uint32_t to = programmed_end(flash, slot, static_cast<std::uint64_t>(written) + bytes);
  std::uint64_t ms = 0;
  for (std::uint32_t erased = erased_end(flash, slot, from); erased < to;) {
    const std::size_t i = flash::sector_of(sectors, erased);
    if (i == sectors.size()) break;
    ms += sectors[i].erase_max_ms;
    erased = sectors[i].offset + sectors[i].size;
  }
  ms += (static_cast<std::uint64_t>(to - from) * flash.program_max_us_per_byte() + 999) / 1000;
  return ms > 0xFFFFFFFFu ? 0xFFFFFFFFu : static_cast<std::uint32_t>(ms);
}

bool append_failed_in_erase(const flash::FlashDevice& flash, const flash::FlashRegion& slot, std::uint32_t written,
                            std::size_t bytes, const model_update::FlashCounters& done) noexcept {
  const std::span<const flash::FlashSector> sectors = flash.sectors();
  const std::uint32_t from = programmed_end(flash, slot, written);
  const std::uint32_t to = programmed_end(flash, slot, static_cast<std::uint64_t>(written) + bytes);
  std::uint32_t erases = 0;
  for (std::uint32_t erased = erased_end(flash, slot, from); erased < to; ++erases) {
    const std::size_t i = flash::sector_of(sectors, erased);
    if (i == sectors.size()) break;
    if (erases == done.erases) {
      // The next operation in order is this erase, unless a program of the
      // bytes below this sector (all programmed before it) failed first.
      const std::uint32_t below = sectors[i].offset > from ? sectors[i].offset - from : 0;
      return done.programmed_bytes >= below;
    }
    erased = sectors[i].offset + sectors[i].size;
  }
  return false;  // every erase of the append completed: a program failed
}

}  // namespace hadynet::usb
