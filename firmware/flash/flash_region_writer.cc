#include "firmware/flash/flash_region_writer.h"

namespace hadynet::flash {

bool region_is_sector_aligned(std::span<const FlashSector> sectors, const FlashRegion& region) noexcept {
  if (region.size == 0) return false;
  bool start_ok = false;
  bool end_ok = false;
  const std::uint64_t end = static_cast<std::uint64_t>(region.offset) + region.size;
  for (const FlashSector& s : sectors) {
    if (s.offset == region.offset) start_ok = true;
    if (static_cast<std::uint64_t>(s.offset) + s.size == end) end_ok = true;
  }
  return start_ok && end_ok;
}

WriteResult FlashRegionWriter::begin(FlashDevice& device, const FlashRegion& region, std::uint32_t start) noexcept {
  device_ = &device;
  region_ = region;
  alignment_ = device.program_alignment();
  start_ = position_ = start;
  erased_end_ = 0;
  held_ = 0;
  if (alignment_ == 0 || alignment_ > kMaxAlignment || region.offset % alignment_ != 0 || start % alignment_ != 0) {
    return {FlashStatus::kMisaligned, false};
  }
  if (!region_is_sector_aligned(device.sectors(), region) || start > region.size) {
    return {FlashStatus::kOutOfRange, false};
  }
  return {};
}

WriteResult FlashRegionWriter::append(std::span<const std::uint8_t> bytes) noexcept {
  if (device_ == nullptr) return {FlashStatus::kOutOfRange, false};
  if (bytes.size() > region_.size - position_ - held_) return {FlashStatus::kOutOfRange, false};
  while (!bytes.empty()) {
    if (held_ > 0 || bytes.size() < alignment_) {
      while (held_ < alignment_ && !bytes.empty()) {
        held_bytes_[held_++] = bytes.front();
        bytes = bytes.subspan(1);
      }
      if (held_ < alignment_) break;
      const WriteResult r = program_range(position_, std::span<const std::uint8_t>(held_bytes_, alignment_));
      if (!r.ok()) return r;
      position_ += alignment_;
      held_ = 0;
      continue;
    }
    const std::size_t n = bytes.size() - bytes.size() % alignment_;
    const WriteResult r = program_range(position_, bytes.first(n));
    if (!r.ok()) return r;
    position_ += static_cast<std::uint32_t>(n);
    bytes = bytes.subspan(n);
  }
  return {};
}

WriteResult FlashRegionWriter::finish() noexcept {
  if (device_ == nullptr) return {FlashStatus::kOutOfRange, false};
  if (held_ == 0) return {};
  for (std::size_t i = held_; i < alignment_; ++i) held_bytes_[i] = 0xFF;
  const WriteResult r = program_range(position_, std::span<const std::uint8_t>(held_bytes_, alignment_));
  if (!r.ok()) return r;
  position_ += alignment_;
  held_ = 0;
  return {};
}

WriteResult FlashRegionWriter::write_at(std::uint32_t at, std::span<const std::uint8_t> bytes) noexcept {
  if (device_ == nullptr) return {FlashStatus::kOutOfRange, false};
  if (at > start_ || bytes.size() > start_ - at) return {FlashStatus::kOutOfRange, false};
  return program_range(at, bytes);
}

std::uint32_t FlashRegionWriter::estimate_append_ms(std::size_t bytes) const noexcept {
  if (device_ == nullptr) return 0;
  const std::span<const FlashSector> sectors = device_->sectors();
  std::uint64_t ms = 0;
  // The stream programs at most up to position_ + held_ + bytes.
  const std::uint64_t end = static_cast<std::uint64_t>(region_.offset) + position_ + held_ + bytes;
  std::uint64_t erased = static_cast<std::uint64_t>(region_.offset) + erased_end_;
  while (erased < end && erased < static_cast<std::uint64_t>(region_.offset) + region_.size) {
    const std::size_t i = sector_of(sectors, static_cast<std::uint32_t>(erased));
    if (i == sectors.size()) break;
    ms += sectors[i].erase_max_ms;
    erased = static_cast<std::uint64_t>(sectors[i].offset) + sectors[i].size;
  }
  ms += (static_cast<std::uint64_t>(bytes) * device_->program_max_us_per_byte() + 999) / 1000;
  return static_cast<std::uint32_t>(ms);
}

WriteResult FlashRegionWriter::ensure_erased(std::uint32_t end) noexcept {
  const std::span<const FlashSector> sectors = device_->sectors();
  while (erased_end_ < end) {
    const std::size_t i = sector_of(sectors, region_.offset + erased_end_);
    if (i == sectors.size()) return {FlashStatus::kOutOfRange, true};
    const FlashStatus s = device_->erase_sector(i);
    if (s != FlashStatus::kOk) return {s, true};
    erased_end_ = sectors[i].offset + sectors[i].size - region_.offset;
  }
  return {};
}

WriteResult FlashRegionWriter::program_range(std::uint32_t at, std::span<const std::uint8_t> bytes) noexcept {
  const std::span<const FlashSector> sectors = device_->sectors();
  while (!bytes.empty()) {
    const std::uint32_t device_offset = region_.offset + at;
    const std::size_t i = sector_of(sectors, device_offset);
    if (i == sectors.size()) return {FlashStatus::kOutOfRange, false};
    const std::uint32_t room = sectors[i].offset + sectors[i].size - device_offset;
    const std::size_t n = bytes.size() < room ? bytes.size() : room;
    const WriteResult e = ensure_erased(at + static_cast<std::uint32_t>(n));
    if (!e.ok()) return e;
    const FlashStatus s = device_->program(device_offset, bytes.first(n));
    if (s != FlashStatus::kOk) return {s, false};
    at += static_cast<std::uint32_t>(n);
    bytes = bytes.subspan(n);
  }
  return {};
}

}  // namespace hadynet::flash
