// The firmware runtime instantiated for the build's generated models (q15
// and f32), compiled with the firmware's flags. The library built from this
// file is what the allocation check inspects: every member function of the
// runtime, network, detector and stabiliser is in it.
#include "firmware/core/hadynet_runtime.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"

template class hadynet::firmware::HadynetRuntime<hadynet::model_q15::Model>;
template class hadynet::firmware::HadynetRuntime<hadynet::model_f32::Model>;
