// The board's USB device port (docs/architecture.md §6): what the firmware's USB side
// (firmware/app/usb_link.cc) needs from a board that has one. Only boards
// whose board.cmake sets BOARD_HAS_USB implement it; boards/CMakeLists.txt
// links usb_link.cc into their firmware image and usb_link_none.cc into the
// others' (mps2-an386: the link stays on the UART).
//
// Threading: main loop only, like boards/board.h.
#ifndef HADYNET_BOARDS_BOARD_USB_H_
#define HADYNET_BOARDS_BOARD_USB_H_

#include <cstdint>
#include <span>

#include "firmware/usb/device_controller.h"
#include "firmware/usb/dfu_runtime.h"
#include "firmware/usb/hadynet_usb_device.h"

namespace hadynet::board {

// Everything lives in static storage and outlives the firmware. The model
// slots behind the DFU-mode interface are not the port's: they are
// board::model_flash() (boards/board.h), which the application's ModelSlots
// manages (firmware/app/usb_link.h).
struct UsbPort {
  usb::DeviceController& controller;
  usb::DetachHook& detach;  // DFU_DETACH: reboot into the ROM bootloader
  std::span<const std::uint8_t, usb::kUniqueIdBytes> unique_id;  // serial number string
};

// The port, or nullptr if its controller does not answer on the bus (an
// emulator without it: QEMU's netduinoplus2 models no OTG FS and no unique
// ID). The controller's clocks and pins are not touched yet (the stack's
// start() calls its init()). Call once, after init().
const UsbPort* usb_port() noexcept;

// Hands the controller's pending events to the stack (main loop, before the
// stack's service()).
void usb_poll() noexcept;

}  // namespace hadynet::board

#endif  // HADYNET_BOARDS_BOARD_USB_H_
