// Strict reader and writer of the safetensors format
// (https://github.com/huggingface/safetensors), used for model files.
//
// File layout: an 8-byte little-endian unsigned header length N, N bytes of a
// UTF-8 JSON object (the header), then the data buffer. Every header key except
// "__metadata__" names a tensor and maps to
//   {"dtype": "F32", "shape": [d0, d1, ...], "data_offsets": [begin, end]}
// where [begin, end) is a byte range of the data buffer (offsets relative to
// its start). "__metadata__" is an optional object of string -> string.
// Tensor payloads are row-major, little-endian.
//
// The reader accepts only what the format allows: every error (short file,
// absurd header length, bad JSON, duplicate keys, unknown keys or dtypes,
// bad shapes or offsets, overlapping tensors, gaps or trailing bytes in the
// buffer, ...) is a FormatError naming the file and, when relevant, the tensor.
//
// The writer is deterministic: header keys sorted, tensors laid out in name
// order, back to back from offset 0 with no gaps, and the header padded with
// spaces to a multiple of 8 bytes so the data buffer starts 8-byte aligned in
// the file. parse(serialize(f)) reproduces f's metadata and tensors exactly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace hadynet::trainer::safetensors {

// The one error type: what() is "ORIGIN: MESSAGE" ("MESSAGE" when origin is
// empty). Example: "model.safetensors: tensor 'enc.weight' has shape
// [128, 44], expected [128, 45]".
class FormatError : public std::runtime_error {
 public:
  FormatError(std::string origin, std::string message);

  // The file (or other source) the error is about; may be empty.
  const std::string& origin() const noexcept { return origin_; }
  // The message alone, without the origin prefix.
  const std::string& message() const noexcept { return message_; }

 private:
  std::string origin_;
  std::string message_;
};

// The supported element types; their names in the header are "F32", "F64",
// "I32", "I64", "U8". Other safetensors dtypes (F16, BF16, BOOL, ...) are
// rejected by the reader as unsupported.
enum class DType { kF32, kF64, kI32, kI64, kU8 };

// "F32" etc.
std::string_view dtype_name(DType dtype);
// Bytes per element: 4, 8, 4, 8, 1.
std::size_t dtype_size(DType dtype);
// The DType named `name` (exact, case-sensitive), or nullopt.
std::optional<DType> dtype_from_name(std::string_view name);

struct Tensor {
  DType dtype = DType::kF32;
  std::vector<std::int64_t> shape;  // empty: a rank-0 scalar (one element)
  std::vector<std::uint8_t> bytes;  // elements() * dtype_size(dtype) bytes, row-major, LE

  // Product of the shape (1 for rank 0). Throws std::invalid_argument if a
  // dimension is negative or the product does not fit in int64.
  std::int64_t elements() const;

  bool operator==(const Tensor&) const = default;
};

struct File {
  std::map<std::string, std::string> metadata;  // "__metadata__"; omitted when empty
  std::map<std::string, Tensor> tensors;        // by name; "__metadata__" is not a valid name
  // Where the file came from (parse's `origin`, read_file's path), used to
  // prefix errors of as_f32() etc. Not serialized; empty for a File built in memory.
  std::string origin;
};

// Tensors from values in row-major order. Throw std::invalid_argument if a
// dimension is negative or the product of `shape` differs from values.size().
Tensor make_f32(std::vector<std::int64_t> shape, std::span<const float> values);
Tensor make_f64(std::vector<std::int64_t> shape, std::span<const double> values);
Tensor make_i32(std::vector<std::int64_t> shape, std::span<const std::int32_t> values);

// The values of tensor `name` of `file` (row-major), after checking that its
// shape equals `expected_shape`. as_f32 accepts F32 and F64 tensors (F64 values
// are rounded to nearest; a finite value beyond the float range is an error),
// as_f64 accepts F32 (exact) and F64, as_i32 only I32. Throws FormatError
// (origin: file.origin) naming the tensor when it is missing, has another
// shape or a dtype that does not convert.
std::vector<float> as_f32(const File& file, const std::string& name,
                          const std::vector<std::int64_t>& expected_shape);
std::vector<double> as_f64(const File& file, const std::string& name,
                           const std::vector<std::int64_t>& expected_shape);
std::vector<std::int32_t> as_i32(const File& file, const std::string& name,
                                 const std::vector<std::int64_t>& expected_shape);

// The bytes of the safetensors file holding `file` (origin is ignored).
// Throws FormatError (with `origin_for_errors`) if a tensor is named
// "__metadata__", a tensor's bytes.size() does not match its dtype and shape,
// a shape has a negative dimension, or a name or metadata string is not valid UTF-8.
std::string serialize(const File& file, const std::string& origin_for_errors = "");

// Reads a safetensors file from its bytes. `origin` (usually the file name)
// prefixes error messages and is stored in File::origin. Throws FormatError.
File parse(std::string_view bytes, const std::string& origin);

// Largest file read_bytes() and read_file() accept: 256 MiB. The hand's
// model is 0.36 MiB; a model with hidden = 1024 (the model reader's limit)
// and its optimiser state in a checkpoint stays below 200 MiB.
inline constexpr std::size_t kMaxFileBytes = std::size_t{256} << 20;

// The bytes of the file at `path`, at most kMaxFileBytes: a larger file or an
// endless one (/dev/zero, a pipe) is a FormatError naming `path`, after
// reading no more than kMaxFileBytes + 64 KiB.
std::string read_bytes(const std::string& path);

// parse() of read_bytes(path); errors (also I/O errors) name `path`.
File read_file(const std::string& path);

// Writes serialize(file) to `path` atomically: the bytes go to a new
// temporary file in the same directory, are flushed to disk (fsync), then the
// temporary file is renamed over `path`. A crash at any point leaves either the
// old file or the complete new one under `path`, never a partial file. On an
// error nothing under `path` changes and the temporary file is removed; throws
// FormatError naming `path`.
void write_file(const std::string& path, const File& file);

}  // namespace hadynet::trainer::safetensors
