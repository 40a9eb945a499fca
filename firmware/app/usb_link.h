// The firmware's USB side: the composite device (firmware/usb/: CDC-ACM
// carrying the link, HID telemetry, DFU runtime and the DFU model
// interface) on the board's USB port (boards/board_usb.h), serving the same
// device state as the UART (one LinkDispatcher: one runtime, one autonomous
// loop), and taking model images into the model slots through the
// application's ModelSlots (firmware/model_update/model_slots.h).
//
// Two implementations, chosen by the build per board: usb_link.cc for a
// board with BOARD_HAS_USB (stm32f405), usb_link_none.cc (every call does
// nothing) for the others (mps2-an386). So firmware_main.cc stays portable.
//
//   usb_start(dispatcher, slots); once, after board::init() and the boot rule
//   loop: usb_service();          every pass of the main loop
//         usb_publish(record);    once per period, after end_period()
#ifndef HADYNET_FIRMWARE_APP_USB_LINK_H_
#define HADYNET_FIRMWARE_APP_USB_LINK_H_

#include "firmware/app/period_record.h"
#include "firmware/link/dispatcher.h"
#include "firmware/model_update/model_slots.h"
#include "hadynet_model_q15.h"

namespace hadynet::app {

using FirmwareModel = model_q15::Model;

// Brings the USB device up (controller init, pull-up on). `dispatcher`
// must outlive the firmware (static storage). `slots`: the ModelSlots over
// board::model_flash() after its boot() (the configuration string names the
// model it chose; DFU downloads go through it), or null: no model updates
// (a board without model flash; the DFU model interface refuses them).
void usb_start(link::LinkDispatcher<FirmwareModel>& dispatcher, model_update::ModelSlots* slots) noexcept;
// Controller events, CDC bytes through the link, DFU flash work.
void usb_service() noexcept;
// The period's record as HID telemetry (dropped while not configured).
void usb_publish(const PeriodRecord<FirmwareModel>& record) noexcept;

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_USB_LINK_H_
