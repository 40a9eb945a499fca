#include "firmware/usb/slot_image_file.h"

#include <array>

#include "firmware/model_update/model_image.h"
#include "firmware/model_update/slot_layout.h"

namespace hadynet::usb {

namespace mu = model_update;

flash::FlashStatus slot_image_file_size(const flash::FlashDevice& flash, const flash::FlashRegion& slot,
                                        std::uint32_t& size) noexcept {
  size = 0;
  if (slot.size < mu::kSlotPayloadOffset) return flash::FlashStatus::kOk;
  std::array<std::uint8_t, mu::kImageHeaderSize> bytes{};
  const flash::FlashStatus s = flash.read(slot.offset + mu::kSlotHeaderOffset, bytes);
  if (s != flash::FlashStatus::kOk) return s;
  mu::ModelImageHeader header;
  if (mu::decode_model_image_header(bytes, header) != mu::HeaderFormat::kWellFormed) return flash::FlashStatus::kOk;
  if (header.payload_length > slot.size - mu::kSlotPayloadOffset) return flash::FlashStatus::kOk;
  size = static_cast<std::uint32_t>(mu::kImageHeaderSize) + header.payload_length;
  return flash::FlashStatus::kOk;
}

flash::FlashStatus read_slot_image_file(const flash::FlashDevice& flash, const flash::FlashRegion& slot,
                                        std::uint32_t file_size, std::uint32_t file_offset,
                                        std::span<std::uint8_t> out) noexcept {
  if (file_offset > file_size || out.size() > file_size - file_offset) return flash::FlashStatus::kOutOfRange;
  constexpr auto kHeader = static_cast<std::uint32_t>(mu::kImageHeaderSize);
  // The part inside the header, then the part inside the payload.
  if (file_offset < kHeader && !out.empty()) {
    const std::uint32_t n = out.size() < kHeader - file_offset ? static_cast<std::uint32_t>(out.size())
                                                               : kHeader - file_offset;
    const flash::FlashStatus s = flash.read(slot.offset + mu::kSlotHeaderOffset + file_offset, out.first(n));
    if (s != flash::FlashStatus::kOk) return s;
    out = out.subspan(n);
    file_offset += n;
  }
  if (out.empty()) return flash::FlashStatus::kOk;
  return flash.read(slot.offset + mu::kSlotPayloadOffset + (file_offset - kHeader), out);
}

}  // namespace hadynet::usb
