// The application's self-test of a model image on trial (implemented by the
// app, firmware/app/model_store.h: run the model through a fixed synthetic
// sequence and compare the low 32 bits of its results' checksum with
// header.self_test_checksum). Called once per trial by ModelSlots::boot(), after the slot was
// marked "tried" and before it is used; `payload` is the verified payload
// in the mapped flash view. true = pass (the image is confirmed), false =
// fail (the image is marked invalid and the boot chooses again). A crash or
// power loss inside run() leaves the image tried but unconfirmed: the next
// boot invalidates it.
#ifndef HADYNET_FIRMWARE_MODEL_UPDATE_SELF_TEST_H_
#define HADYNET_FIRMWARE_MODEL_UPDATE_SELF_TEST_H_

#include <cstdint>
#include <span>

#include "firmware/model_update/model_image.h"

namespace hadynet::model_update {

class SelfTest {
 public:
  virtual bool run(std::span<const std::uint8_t> payload, const ModelImageHeader& header) noexcept = 0;

 protected:
  ~SelfTest() = default;
};

}  // namespace hadynet::model_update

#endif  // HADYNET_FIRMWARE_MODEL_UPDATE_SELF_TEST_H_
