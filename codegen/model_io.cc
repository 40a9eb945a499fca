#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "codegen/codegen.h"
#include "datalog/atomic_file.h"
#include "datalog/content_hash.h"
#include "trainer/model_file.h"
#include "trainer/safetensors.h"

namespace hadynet::codegen {

namespace fs = std::filesystem;

LoadedModel load_model_file(const std::string& path) {
  std::string bytes;
  trainer::safetensors::File file;
  try {
    bytes = trainer::safetensors::read_bytes(path);
    file = trainer::safetensors::parse(bytes, path);
  } catch (const trainer::safetensors::FormatError& e) {
    throw trainer::ModelFileError(e.what());
  }
  LoadedModel loaded{trainer::model_from_safetensors(file, path), {}};
  loaded.identity.file_name = fs::path(path).filename().string();
  loaded.identity.hash = datalog::fnv1a64(bytes);
  return loaded;
}

WriteResult write_header(const std::string& dir, const GeneratedHeader& header) {
  const fs::path path = fs::path(dir) / header.file_name;
  WriteResult result{path.string(), false};
  {
    std::ifstream old(path, std::ios::binary);
    if (old) {
      const std::string text{std::istreambuf_iterator<char>(old), std::istreambuf_iterator<char>()};
      if (text == header.text) return result;
    }
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create the directory: " + ec.message());
  try {
    datalog::write_file_atomically(path, header.text);
  } catch (const datalog::AtomicWriteError& e) {
    throw std::runtime_error(std::string("cannot write the generated header: ") + e.what());
  }
  result.changed = true;
  return result;
}

}  // namespace hadynet::codegen
