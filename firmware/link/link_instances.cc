// The link instantiated for the build's generated models (q15 and f32),
// compiled with the firmware's flags. The library built from this file is
// what the allocation check inspects: the dispatcher, the device end
// (stream decoder, COBS, CRC) and the host end, and through them the runtime.
#include "firmware/link/device_link.h"
#include "firmware/link/dispatcher.h"
#include "firmware/link/link_client.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"

template class hadynet::link::LinkDispatcher<hadynet::model_q15::Model>;
template class hadynet::link::LinkDispatcher<hadynet::model_f32::Model>;
template class hadynet::link::DeviceLink<hadynet::model_q15::Model>;
template class hadynet::link::DeviceLink<hadynet::model_f32::Model>;
template class hadynet::link::LinkClient<hadynet::model_q15::Model>;
template class hadynet::link::LinkClient<hadynet::model_f32::Model>;
