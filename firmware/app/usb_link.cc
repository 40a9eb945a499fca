// The firmware's USB side on a board with a USB port (firmware/app/usb_link.h).
// All objects are static; the composite device is constructed in place by
// usb_start(), after board::init() (it needs the board's port), so nothing
// here runs before main().
#include "firmware/app/usb_link.h"

#include <new>

#include "boards/board.h"
#include "boards/board_usb.h"
#include "firmware/link/frame.h"
#include "firmware/link/link_port.h"
#include "firmware/usb/hadynet_usb_device.h"

#ifndef HADYNET_FIRMWARE_VERSION
#error "the build defines HADYNET_FIRMWARE_VERSION (the project's version)"
#endif

namespace hadynet::app {
namespace {

using Port = link::LinkPort<FirmwareModel>;
using Usb = usb::HadynetUsbDevice<FirmwareModel, Port, link::kMaxWireFrame>;

// Storage for objects built by usb_start() (placement new: no heap; never
// destroyed, like every static of the firmware).
alignas(Port) unsigned char g_port_storage[sizeof(Port)];
alignas(Usb) unsigned char g_usb_storage[sizeof(Usb)];
Usb* g_usb = nullptr;

}  // namespace

void usb_start(link::LinkDispatcher<FirmwareModel>& dispatcher, model_update::ModelSlots* slots) noexcept {
  if (g_usb != nullptr) return;
  const board::UsbPort* port = board::usb_port();
  if (port == nullptr) return;  // no controller on the bus: the UART alone
  // The slots live on the board's model flash; DFU uploads read them there.
  const board::ModelFlash* model_flash = slots != nullptr ? board::model_flash() : nullptr;
  const usb::ModelSlotsAccess model{model_flash != nullptr ? slots : nullptr,
                                    model_flash != nullptr ? &model_flash->device : nullptr};
  Port* link_port = new (g_port_storage) Port(dispatcher);
  g_usb = new (g_usb_storage)
      Usb(port->controller, *link_port, model, port->detach, port->unique_id, HADYNET_FIRMWARE_VERSION);
  g_usb->start();
}

void usb_service() noexcept {
  if (g_usb == nullptr) return;
  board::usb_poll();
  g_usb->service();
}

void usb_publish(const PeriodRecord<FirmwareModel>& record) noexcept {
  if (g_usb != nullptr) g_usb->publish(record);
}

}  // namespace hadynet::app
