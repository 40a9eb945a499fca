// The shape id of a generated header (kShapeId, docs/model-update.md): a
// hash of every member of `struct Model` that is not model data. Two models
// with the same shape id can share one firmware image: the data members of
// one (ModelTensors, firmware/core/model_tensors.h) run in the other's
// firmware, which is what a model image carries. Anything not listed as data
// here (dimensions, formats, channel names and layout, loss classes, derived
// inputs, counts and channels of the sensor model, control constants, the
// period, detection on/off) is shape, so a member added to the contract
// later is shape until it is listed as data.
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace hadynet::codegen {

// The members whose values a model image replaces.
const std::set<std::string>& data_members();
// Members that name where the header came from, neither shape nor data
// (kGeneratorVersion, kModelHash, kShapeId itself).
const std::set<std::string>& identity_members();

// FNV-1a 64 of "name=item,item,...;" for every member that is neither data
// nor identity, in name order. `literals` as Emitter::literals.
std::uint64_t shape_id(const std::map<std::string, std::vector<std::string>>& literals);

}  // namespace hadynet::codegen
