// HADYNET codegen (docs/method.md, "Network"; docs/architecture.md §6; docs/codegen.md): a trained model file
// -> one allocation-free C++ header holding one struct of static constexpr
// constants and arrays that satisfies hadynet::firmware::GeneratedModel
// (firmware/core/model_contract.h, the specification of every member).
//
// generate() runs three steps: prepare (prepared_model.h: check the model and
// the options, fold the batch norm, whiten the detection statistics, weigh
// the loss, once), quantise (formats.h chooses the formats, tensor_writer.h
// rounds every tensor into them) and emit (header_text.h). load_model_file
// and write_header (model_io.cc) are its only I/O.
//
// Everything here is pure: the same model, hash and options give the same
// text, byte for byte. An unsupported or malformed model is rejected with
// UnsupportedModel before any text exists, so a caller that writes only
// after generate() returned never leaves a partial or stale file.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "codegen/codegen_options.h"
#include "codegen/formats.h"
#include "codegen/unsupported_model.h"
#include "firmware/core/model_contract.h"
#include "trainer/hadynet_model.h"

namespace hadynet::codegen {

using hadynet::firmware::numeric_name;  // "q15" or "f32"

// The namespace the header uses (options.ns or the default).
std::string namespace_of(const CodegenOptions& options);

// The file the header is written to: "hadynet_model_q15.h" / "hadynet_model_f32.h".
std::string header_file_name(Numeric numeric);

// The formats generate() would choose for `model` (checks the model and the
// options first; throws UnsupportedModel).
Formats choose_formats(const trainer::HadynetModel& model, const CodegenOptions& options);

// Where the model came from, stamped into the header.
struct ModelIdentity {
  std::string file_name;  // shown in the header comment (a base name keeps it build-dir independent)
  std::uint64_t hash = 0; // datalog::fnv1a64 of the model file's bytes (kModelHash)
};

struct GeneratedHeader {
  std::string file_name;  // header_file_name(options.numeric)
  std::string text;       // the whole header
  Formats formats;        // as chosen (all frac 0 in an f32 header's constants)
  std::uint64_t shape_id = 0;  // kShapeId (codegen/shape_id.h)
  // Every member's literals by name, arrays flattened row by row, as in the
  // text (header_text.h's Emitter::literals): the model image writer's input.
  std::map<std::string, std::vector<std::string>> literals;
};

// The header for `model` (throws UnsupportedModel before producing anything).
GeneratedHeader generate(const trainer::HadynetModel& model, const ModelIdentity& identity,
                         const CodegenOptions& options);

// A model file read for codegen: the model and the identity of its bytes.
struct LoadedModel {
  trainer::HadynetModel model;
  ModelIdentity identity;
};
// Reads the file once, hashes those bytes and parses them (trainer/model_file.h).
// Throws trainer::ModelFileError naming the path.
LoadedModel load_model_file(const std::string& path);

// Writes header.text to dir/header.file_name atomically (a temporary file in
// dir, then rename); creates dir if needed. An existing file with the same
// text is left untouched (so nothing that includes it rebuilds). Returns the
// path and whether the file changed. Throws std::runtime_error naming the path.
struct WriteResult {
  std::string path;
  bool changed = false;
};
WriteResult write_header(const std::string& dir, const GeneratedHeader& header);

}  // namespace hadynet::codegen
