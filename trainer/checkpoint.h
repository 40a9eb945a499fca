// Training checkpoints: a model file (model_file.h) that also carries the
// Adam state as tensors "optim.adam.m.<tensor>" / "optim.adam.v.<tensor>"
// and, in metadata "checkpoint", the epochs done, Adam step counts, the
// options that must not change on resume, and the loss history. load_model
// rejects a checkpoint (its optim.* tensors); load_checkpoint reads it, and
// `hadynet train` writes the plain model file at the end.
#pragma once

#include <string>

#include "trainer/hadynet_model.h"
#include "trainer/training.h"

namespace hadynet::trainer {

struct Checkpoint {
  HadynetModel model;
  TrainingState state;
  TrainOptions options;  // epochs may be raised on resume; the rest must match
};

// Atomic: a kill during the write leaves the previous checkpoint intact.
void save_checkpoint(const std::string& path, const Checkpoint& checkpoint);
// Throws ModelFileError naming the path for anything malformed.
Checkpoint load_checkpoint(const std::string& path);

}  // namespace hadynet::trainer
