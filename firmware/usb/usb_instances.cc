// The USB stack instantiated with the firmware's flags for the build's q15
// model and the link's device end: the composite device, every function,
// the telemetry encoder and decoder, the host backend (fake controller) and
// the simulated flash. The library built from this file (with usb_device.cc,
// dfu_mode.cc and the flash sources) is what the allocation check inspects,
// on the host and in the Cortex-M4 cross build.
#include "firmware/link/device_link.h"
#include "firmware/link/frame.h"
#include "firmware/usb/hadynet_usb_device.h"
#include "firmware/usb/telemetry_decoder.h"
#include "hadynet_model_q15.h"

namespace hadynet::usb {

template class CdcAcm<link::DeviceLink<model_q15::Model>, link::kMaxWireFrame>;
template class HidTelemetry<model_q15::Model>;
template class HadynetUsbDevice<model_q15::Model, link::DeviceLink<model_q15::Model>, link::kMaxWireFrame>;
template class TelemetryDecoder<model_q15::Model>;

}  // namespace hadynet::usb
