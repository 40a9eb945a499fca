// Model images for a firmware of shape M (docs/model-update.md): a new
// model's generated header (codegen::generate with M's formats) becomes the
// bytes of a ModelTensors<M> (firmware/core/model_tensors.h) behind a signed
// header (firmware/model_update/model_image.h). The payload is built, and
// its self-test run, by the firmware's own sources compiled for the PC, so
// the device reads exactly these tensors and computes exactly this
// checksum (bit-identical q15; the f32 build's checksum depends on the C
// library's transcendental functions, so an f32 image is for host-sim).
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "codegen/codegen.h"
#include "firmware/app/runtime_checksum.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_tensors.h"
#include "firmware/model_update/model_image.h"
#include "host-sim/model_image/row_major_model.h"
#include "host-sim/model_image/signing_key.h"

namespace hadynet::host {

// A model that cannot become an image for this firmware (another shape).
class ModelImageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ModelImageRequest {
  std::uint32_t sequence = 1;    // >= 1; the device refuses one not above its newest (docs)
  bool allow_downgrade = false;  // signed flag: the device accepts a lower sequence
};

struct ModelImage {
  model_update::ModelImageHeader header;
  std::vector<std::uint8_t> bytes;  // header (256) + payload
  std::uint64_t self_test_checksum = 0;  // app::runtime_checksum; the header keeps its low 32 bits
};

// M's q15 formats in CodegenOptions::target_formats' order.
template <firmware::GeneratedModel M>
constexpr std::array<int, 12> firmware_formats() {
  return {M::kFracIn,    M::kFracH,      M::kFracC,      M::kFracY,     M::kFracGate, M::kFracEncW,
          M::kFracLstmW, M::kFracLstmAcc, M::kFracDecW, M::kFracWhiten, M::kFracZ,  M::kFracLossW};
}

// The payload for `header` (a header generated for shape M): its data as
// ModelTensors<M> bytes. Throws ModelImageError (another shape) or
// ModelLiteralError.
template <firmware::GeneratedModel M>
std::unique_ptr<firmware::ModelTensors<M>> tensors_of(const codegen::GeneratedHeader& header) {
  if (header.shape_id != M::kShapeId) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "the model's shape id 0x%016llx is not this firmware's 0x%016llx",
                  static_cast<unsigned long long>(header.shape_id), static_cast<unsigned long long>(M::kShapeId));
    std::string why = buf;
    const auto dim = [&](const char* name, int firmware) {
      const auto it = header.literals.find(name);
      if (it != header.literals.end() && it->second.size() == 1 && it->second[0] != std::to_string(firmware))
        why += std::string("; ") + name + " " + it->second[0] + " (firmware " + std::to_string(firmware) + ")";
    };
    dim("kX", M::kX);
    dim("kU", M::kU);
    dim("kY", M::kY);
    dim("kPb", M::kPb);
    dim("kHidden", M::kHidden);
    dim("kStates", M::kStates);
    dim("kTrainSteps", M::kTrainSteps);
    dim("kDetectSteps", M::kDetectSteps);
    dim("kControlHorizon", M::kControlHorizon);
    dim("kControlAlphaCount", M::kControlAlphaCount);
    throw ModelImageError(why + ": channels, sensor model, control options or period differ (compare the "
                                "generated headers); build a firmware for this model instead");
  }
  auto source = std::make_unique<RowMajorModel<M>>();
  source->read(header.literals);
  // Value-initialised: every byte zero first, so the payload's bytes
  // (padding included) are a function of the model alone.
  auto tensors = std::make_unique<firmware::ModelTensors<M>>();
  std::memset(static_cast<void*>(tensors.get()), 0, sizeof(firmware::ModelTensors<M>));
  firmware::build_tensors<M>(*source, *tensors);
  return tensors;
}

// The runtime's checksum over the fixed self-test run (app::runtime_checksum)
// with `tensors`: what the device computes before it confirms the image.
template <firmware::GeneratedModel M>
std::uint64_t self_test_checksum(const firmware::ModelTensors<M>& tensors) {
  auto runtime = std::make_unique<firmware::HadynetRuntime<M>>(tensors);
  return app::runtime_checksum(*runtime);
}

// The signed image of `header` for a firmware of shape M.
template <firmware::GeneratedModel M>
ModelImage make_model_image(const codegen::GeneratedHeader& header, const SigningKey& key,
                            const ModelImageRequest& request) {
  if (request.sequence == 0) throw ModelImageError("model image: the sequence number must be at least 1");
  const auto tensors = tensors_of<M>(header);
  ModelImage image;
  image.self_test_checksum = self_test_checksum<M>(*tensors);
  const auto* payload = reinterpret_cast<const std::uint8_t*>(tensors.get());
  const std::size_t n = sizeof(firmware::ModelTensors<M>);

  model_update::ModelImageHeader& h = image.header;
  h.contract_version = static_cast<std::uint16_t>(M::kContractVersion);
  h.numeric = M::kNumeric == firmware::Numeric::kQ15 ? model_update::kNumericQ15 : model_update::kNumericF32;
  h.downgrade_allowed = request.allow_downgrade;
  h.sequence = request.sequence;
  h.shape_id = M::kShapeId;
  h.payload_length = static_cast<std::uint32_t>(n);
  h.self_test_checksum = static_cast<std::uint32_t>(image.self_test_checksum);
  h.dims = {static_cast<std::uint16_t>(M::kX),       static_cast<std::uint16_t>(M::kU),
            static_cast<std::uint16_t>(M::kY),       static_cast<std::uint16_t>(M::kPb),
            static_cast<std::uint16_t>(M::kHidden),  static_cast<std::uint16_t>(M::kStates),
            static_cast<std::uint16_t>(M::kTrainSteps), static_cast<std::uint16_t>(M::kDetectSteps)};
  const std::array<int, 12> fracs = firmware_formats<M>();
  for (std::size_t i = 0; i < fracs.size(); ++i) h.frac_bits[i] = static_cast<std::uint8_t>(fracs[i]);
  h.model_hash = tensors->model_hash;
  h.public_key = key.public_key;
  h.payload_sha256 = sha256({payload, n});

  std::array<std::uint8_t, model_update::kImageHeaderSize> bytes{};
  model_update::encode_model_image_header(h, bytes);
  h.signature = sign(key, std::span<const std::uint8_t>(bytes.data(), model_update::kSignedBytes));
  model_update::encode_model_image_header(h, bytes);
  image.bytes.assign(bytes.begin(), bytes.end());
  image.bytes.insert(image.bytes.end(), payload, payload + n);
  return image;
}

}  // namespace hadynet::host
