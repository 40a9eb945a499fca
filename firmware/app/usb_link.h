// The firmware's USB side: the composite device (firmware/usb/: CDC-ACM
// carrying the link, HID telemetry, DFU runtime and DFU model slots) on the
// board's USB port (boards/board_usb.h), serving the same device state as
// the UART (one LinkDispatcher: one runtime, one autonomous loop).
//
// Two implementations, chosen by the build per board: usb_link.cc for a
// board with BOARD_HAS_USB (stm32f405), usb_link_none.cc (every call does
// nothing) for the others (mps2-an386). So firmware_main.cc stays portable.
//
//   usb_start(dispatcher);        once, after board::init()
//   loop: usb_service();          every pass of the main loop
//         usb_publish(record);    once per period, after end_period()
#ifndef HADYNET_FIRMWARE_APP_USB_LINK_H_
#define HADYNET_FIRMWARE_APP_USB_LINK_H_

#include "firmware/app/period_record.h"
#include "firmware/link/dispatcher.h"
#include "hadynet_model_q15.h"

namespace hadynet::app {

using FirmwareModel = model_q15::Model;

// Brings the USB device up (controller init, pull-up on). `dispatcher`
// must outlive the firmware (static storage).
void usb_start(link::LinkDispatcher<FirmwareModel>& dispatcher) noexcept;
// Controller events, CDC bytes through the link, DFU flash work.
void usb_service() noexcept;
// The period's record as HID telemetry (dropped while not configured).
void usb_publish(const PeriodRecord<FirmwareModel>& record) noexcept;

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_USB_LINK_H_
