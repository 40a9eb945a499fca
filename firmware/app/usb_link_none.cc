// The firmware's USB side on a board without USB (firmware/app/usb_link.h):
// nothing to do; the link runs on the UART alone.
#include "firmware/app/usb_link.h"

namespace hadynet::app {

void usb_start(link::LinkDispatcher<FirmwareModel>&, model_update::ModelSlots*) noexcept {}
void usb_service() noexcept {}
void usb_publish(const PeriodRecord<FirmwareModel>&) noexcept {}

}  // namespace hadynet::app
