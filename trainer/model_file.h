// The HADYNET model file (docs/model-file.md): safetensors with the network
// tensors under their PyTorch state_dict names and layouts, so that
// `model.load_state_dict(safetensors.torch.load_file(path), strict=False)`
// loads the weights into a torch module with submodules enc, enc_bn, lstm,
// dec and a parameter pb. Everything else (channels, standardisation, PB
// states, detection, hyper-parameters, provenance) is in extra tensors and in
// `__metadata__` as JSON strings.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "trainer/hadynet_model.h"
#include "trainer/safetensors.h"

namespace hadynet::trainer {

inline constexpr const char* kModelFormat = "hadynet-model";
// Format versions. 1: a model without calibration curves; 2: a model whose
// sensor model has calibration curves (a build that reads version 1 only
// would load such a file without its curves and predict wrongly, so it must
// refuse it). A file is written with the lowest version that holds its
// model; this build reads both.
inline constexpr int kModelFormatVersion = 1;
inline constexpr int kModelFormatVersionCurves = 2;

// Thrown for a file that is not a valid HADYNET model; what() starts with
// the path.
class ModelFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Model -> safetensors content (checkpoint.h adds its optim.* tensors to it).
safetensors::File model_to_safetensors(const HadynetModel& model);
// Safetensors content -> model. Rejects (ModelFileError, naming `origin`)
// a wrong format tag or version, missing or extra tensors (except "optim.*"
// when `allow_optimizer_state`), wrong shapes or dtypes, inconsistent
// metadata, and non-finite weights.
HadynetModel model_from_safetensors(const safetensors::File& file, const std::string& origin,
                                    bool allow_optimizer_state = false);

// Atomic write (a crash leaves the previous file or the new one, never a mix).
void save_model(const std::string& path, const HadynetModel& model);
HadynetModel load_model(const std::string& path);

}  // namespace hadynet::trainer
