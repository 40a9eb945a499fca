// The transport envelope of a model image sent over DFU (until the model
// image format of the model-update issue replaces the payload's meaning):
//
//   offset 0  u32 magic 0x4D494448 ("HDIM" in byte order)
//   offset 4  u16 envelope version (1)
//   offset 6  u16 reserved (0)
//   offset 8  u32 payload length n, bytes
//   offset 12 u32 CRC-32 of the payload (firmware/link/crc32.h)
//   offset 16 n payload bytes
//
// The device stores the file as received at the start of the slot, but
// programs the 16 header bytes LAST, after the payload's CRC was checked on
// the received stream and on the flash read back: a slot whose header reads
// back valid holds a complete, checked image; an interrupted download leaves
// the header erased (no image).
#ifndef HADYNET_FIRMWARE_USB_DFU_IMAGE_H_
#define HADYNET_FIRMWARE_USB_DFU_IMAGE_H_

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/usb/usb_spec.h"

namespace hadynet::usb {

inline constexpr std::uint32_t kDfuImageMagic = 0x4D494448u;
inline constexpr std::uint16_t kDfuImageVersion = 1;
inline constexpr std::size_t kDfuImageHeaderSize = 16;

struct DfuImageHeader {
  std::uint32_t magic = kDfuImageMagic;
  std::uint16_t version = kDfuImageVersion;
  std::uint16_t reserved = 0;
  std::uint32_t length = 0;  // payload bytes
  std::uint32_t crc32 = 0;   // of the payload

  // Magic, version and reserved field as written by this version.
  constexpr bool well_formed() const noexcept {
    return magic == kDfuImageMagic && version == kDfuImageVersion && reserved == 0;
  }
};

constexpr void encode_dfu_image_header(const DfuImageHeader& h, std::span<std::uint8_t, kDfuImageHeaderSize> out) noexcept {
  put_u32(out.data(), h.magic);
  put_u16(out.data() + 4, h.version);
  put_u16(out.data() + 6, h.reserved);
  put_u32(out.data() + 8, h.length);
  put_u32(out.data() + 12, h.crc32);
}

constexpr DfuImageHeader decode_dfu_image_header(std::span<const std::uint8_t, kDfuImageHeaderSize> in) noexcept {
  DfuImageHeader h;
  h.magic = get_u32(in.data());
  h.version = get_u16(in.data() + 4);
  h.reserved = get_u16(in.data() + 6);
  h.length = get_u32(in.data() + 8);
  h.crc32 = get_u32(in.data() + 12);
  return h;
}

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_DFU_IMAGE_H_
