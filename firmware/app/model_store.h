// Which model the firmware runs (docs/model-update.md): the compiled-in one
// (the factory default) or a signed model image in one of the two flash
// slots (firmware/model_update/model_slots.h), read in place. The app's
// side of the boot rule: what an image must match (model_identity), how a
// slot's payload is read as tensors (tensors_in), and the self-test a new
// image must pass before it is confirmed (RuntimeSelfTest: the runtime's
// checksum over the fixed synthetic run, app/runtime_checksum.h, equal to
// the one the host computed with the same sources and stored in the
// header). Same sources on the host (tests) and the MCU.
#ifndef HADYNET_FIRMWARE_APP_MODEL_STORE_H_
#define HADYNET_FIRMWARE_APP_MODEL_STORE_H_

#include <cstdint>
#include <span>

#include "firmware/app/runtime_checksum.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_tensors.h"
#include "firmware/model_update/model_identity.h"
#include "firmware/model_update/model_slots.h"
#include "firmware/model_update/self_test.h"

namespace hadynet::app {

// What an image must match to run on a firmware built for M.
template <firmware::GeneratedModel M>
constexpr model_update::ModelIdentity model_identity() noexcept {
  model_update::ModelIdentity id;
  id.contract_version = static_cast<std::uint16_t>(M::kContractVersion);
  id.numeric = M::kNumeric == firmware::Numeric::kQ15 ? model_update::kNumericQ15 : model_update::kNumericF32;
  id.shape_id = M::kShapeId;
  id.payload_length = static_cast<std::uint32_t>(sizeof(firmware::ModelTensors<M>));
  return id;
}

// A verified payload as the tensors it holds, in place; nullptr when its
// size is not this firmware's or it is not aligned for them (slots start on
// sector boundaries and payloads 1024 bytes in, so a real slot always is).
// The payload bytes were written from a ModelTensors<M> of this layout by
// the host (host-sim/model_image/model_image_writer.h): reading them as one
// is what the firmware does with any data in flash.
template <firmware::GeneratedModel M>
const firmware::ModelTensors<M>* tensors_in(std::span<const std::uint8_t> payload) noexcept {
  using T = firmware::ModelTensors<M>;
  if (payload.size() != sizeof(T) || reinterpret_cast<std::uintptr_t>(payload.data()) % alignof(T) != 0) {
    return nullptr;
  }
  return reinterpret_cast<const T*>(payload.data());
}

// The self-test of an image on trial: refuses curve knots the sensor stage
// cannot use (curve_tensors_valid), then runs the fixed synthetic sequence
// (runtime_checksum) on the image's tensors with `runtime` and compares the
// checksum's low 32 bits with the header's. The runtime is given back on the
// compiled-in model in its previous mode (the boot then picks the model).
template <firmware::GeneratedModel M>
class RuntimeSelfTest final : public model_update::SelfTest {
 public:
  explicit RuntimeSelfTest(firmware::HadynetRuntime<M>& runtime) noexcept : runtime_(runtime) {}

  bool run(std::span<const std::uint8_t> payload, const model_update::ModelImageHeader& header) noexcept override {
    const firmware::ModelTensors<M>* tensors = tensors_in<M>(payload);
    if (tensors == nullptr || !firmware::curve_tensors_valid<M>(*tensors)) return false;
    const firmware::Mode mode = runtime_.mode();
    runtime_.use_model(*tensors);
    last_checksum_ = runtime_checksum(runtime_);
    runtime_.use_model(firmware::kCompiledTensors<M>);
    runtime_.set_mode(mode);
    return static_cast<std::uint32_t>(last_checksum_) == header.self_test_checksum;
  }
  std::uint64_t last_checksum() const noexcept { return last_checksum_; }

 private:
  firmware::HadynetRuntime<M>& runtime_;
  std::uint64_t last_checksum_ = 0;
};

// Runs the boot rule on `slots` and makes `runtime` run the chosen model
// (the compiled-in one when no slot holds a usable image). Returns the choice.
template <firmware::GeneratedModel M>
const model_update::BootChoice& boot_model(model_update::ModelSlots& slots,
                                           firmware::HadynetRuntime<M>& runtime) noexcept {
  RuntimeSelfTest<M> self_test(runtime);
  (void)slots.boot(self_test);
  const model_update::BootChoice& choice = slots.choice();
  const firmware::ModelTensors<M>* tensors = tensors_in<M>(choice.payload);
  runtime.use_model(tensors != nullptr ? *tensors : firmware::kCompiledTensors<M>);
  return choice;
}

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_MODEL_STORE_H_
