// A model slot read back as the image file that was written into it
// (docs/usb.md, "Upload"): the slot's header bytes [0, 256) followed by the
// payload at slot offset 1024 (firmware/model_update/slot_layout.h), so
//
//   file [0, 256)          = slot [0, 256)
//   file [256, 256 + n)    = slot [1024, 1024 + n),   n = the header's payload length
//
// and a host compares a read-back with the file it sent byte for byte. The
// trial flags between them are the device's, not the file's, and are not
// part of it. A slot whose header does not decode as a well-formed image
// header (erased: empty, or an update that did not finish), or whose
// payload would not fit the slot, reads as a file of 0 bytes.
#ifndef HADYNET_FIRMWARE_USB_SLOT_IMAGE_FILE_H_
#define HADYNET_FIRMWARE_USB_SLOT_IMAGE_FILE_H_

#include <cstdint>
#include <span>

#include "firmware/flash/flash_device.h"
#include "firmware/flash/flash_region_writer.h"

namespace hadynet::usb {

// The file's size in bytes (0: no image), in `size`; kOk or the read's error.
flash::FlashStatus slot_image_file_size(const flash::FlashDevice& flash, const flash::FlashRegion& slot,
                                        std::uint32_t& size) noexcept;

// File bytes [file_offset, file_offset + out.size()) of a file of
// `file_size` bytes (slot_image_file_size); the range must lie inside it.
flash::FlashStatus read_slot_image_file(const flash::FlashDevice& flash, const flash::FlashRegion& slot,
                                        std::uint32_t file_size, std::uint32_t file_offset,
                                        std::span<std::uint8_t> out) noexcept;

}  // namespace hadynet::usb

#endif  // HADYNET_FIRMWARE_USB_SLOT_IMAGE_FILE_H_
