#include "trainer/safetensors.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <system_error>
#include <tuple>
#include <utility>

#include "datalog/atomic_file.h"

namespace hadynet::trainer::safetensors {

static_assert(std::endian::native == std::endian::little,
              "safetensors payloads are little-endian; this code copies them as host bytes");

namespace {

using Json = nlohmann::json;

// The reference implementation's limit; a larger header is certainly corrupt.
constexpr std::uint64_t kMaxHeaderBytes = 100'000'000;
constexpr std::string_view kMetadataKey = "__metadata__";
constexpr std::uint64_t kInt64Max =
    static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());

std::string compose(const std::string& origin, const std::string& message) {
  return origin.empty() ? message : origin + ": " + message;
}

std::string single_quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

std::string shape_text(const std::vector<std::int64_t>& shape) {
  std::string out = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i != 0) out += ", ";
    out += std::to_string(shape[i]);
  }
  return out + "]";
}

std::string offsets_text(std::uint64_t begin, std::uint64_t end) {
  return "[" + std::to_string(begin) + ", " + std::to_string(end) + "]";
}

// a * b, or nullopt on overflow of uint64.
std::optional<std::uint64_t> checked_mul(std::uint64_t a, std::uint64_t b) {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a) return std::nullopt;
  return a * b;
}

// Product of `shape`, or nullopt if a dimension is negative or the product
// does not fit in int64.
std::optional<std::int64_t> element_count(const std::vector<std::int64_t>& shape) {
  std::uint64_t product = 1;
  for (const std::int64_t d : shape) {
    if (d < 0) return std::nullopt;
    const auto next = checked_mul(product, static_cast<std::uint64_t>(d));
    if (!next || *next > kInt64Max) return std::nullopt;
    product = *next;
  }
  return static_cast<std::int64_t>(product);
}

template <class T>
Tensor make_tensor(DType dtype, std::vector<std::int64_t> shape, std::span<const T> values) {
  const auto count = element_count(shape);
  if (!count) {
    throw std::invalid_argument("safetensors: shape " + shape_text(shape) +
                                " has a negative dimension or too many elements");
  }
  if (static_cast<std::uint64_t>(*count) != values.size()) {
    throw std::invalid_argument("safetensors: shape " + shape_text(shape) + " holds " +
                                std::to_string(*count) + " elements, got " +
                                std::to_string(values.size()) + " values");
  }
  Tensor t;
  t.dtype = dtype;
  t.shape = std::move(shape);
  t.bytes.resize(values.size_bytes());
  if (!values.empty()) std::memcpy(t.bytes.data(), values.data(), values.size_bytes());
  return t;
}

template <class T>
std::vector<T> values_of(const Tensor& t) {
  std::vector<T> out(t.bytes.size() / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), t.bytes.data(), out.size() * sizeof(T));
  return out;
}

// The tensor `name` of `file` after checking its shape (and that its byte
// count matches, for Files built in memory).
const Tensor& checked_tensor(const File& file, const std::string& name,
                             const std::vector<std::int64_t>& expected_shape) {
  const auto it = file.tensors.find(name);
  if (it == file.tensors.end()) {
    throw FormatError(file.origin, "tensor " + single_quoted(name) + " is missing");
  }
  const Tensor& t = it->second;
  if (t.shape != expected_shape) {
    throw FormatError(file.origin, "tensor " + single_quoted(name) + " has shape " +
                                       shape_text(t.shape) + ", expected " +
                                       shape_text(expected_shape));
  }
  const auto count = element_count(t.shape);
  const auto bytes =
      count ? checked_mul(static_cast<std::uint64_t>(*count), dtype_size(t.dtype)) : std::nullopt;
  if (!bytes || *bytes != t.bytes.size()) {
    throw FormatError(file.origin,
                      "tensor " + single_quoted(name) + " holds " + std::to_string(t.bytes.size()) +
                          " bytes, which do not match " + std::string(dtype_name(t.dtype)) +
                          " and shape " + shape_text(t.shape));
  }
  return t;
}

[[noreturn]] void wrong_dtype(const File& file, const std::string& name, DType found,
                              std::string_view accepted) {
  throw FormatError(file.origin, "tensor " + single_quoted(name) + " has dtype " +
                                     std::string(dtype_name(found)) + ", expected " +
                                     std::string(accepted));
}

// ---- parsing ----

// Parser callback enforcing what nlohmann::json does not: no key twice in one
// object (nlohmann would silently keep the last), and nesting no deeper than
// kMaxNesting (valid headers nest 3 deep; this bounds work on hostile input).
// Throws FormatError, which aborts the parse; nlohmann cleans up on unwinding.
class HeaderChecker {
 public:
  static constexpr int kMaxNesting = 32;

  explicit HeaderChecker(const std::string& origin) : origin_(origin) {}

  bool operator()(int depth, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        if (depth >= kMaxNesting) {
          throw FormatError(
              origin_, "JSON header nests deeper than " + std::to_string(kMaxNesting) + " levels");
        }
        if (event == Json::parse_event_t::object_start) frames_.emplace_back();
        break;
      case Json::parse_event_t::key:
        if (!frames_.empty()) {
          Frame& frame = frames_.back();
          frame.last_key = parsed.get<std::string>();
          if (!frame.keys.insert(frame.last_key).second) {
            std::string where;
            for (std::size_t i = 0; i + 1 < frames_.size(); ++i) {
              where += (where.empty() ? "" : " / ") + single_quoted(frames_[i].last_key);
            }
            throw FormatError(origin_, "duplicate key " + single_quoted(frame.last_key) +
                                           " in the JSON header" +
                                           (where.empty() ? "" : " (inside " + where + ")"));
          }
        }
        break;
      case Json::parse_event_t::object_end:
        if (!frames_.empty()) frames_.pop_back();
        break;
      default:
        break;
    }
    return true;  // keep every value
  }

 private:
  struct Frame {
    std::set<std::string> keys;
    std::string last_key;  // the key whose value is being parsed
  };
  const std::string& origin_;
  std::vector<Frame> frames_;  // one per open object
};

// Where one tensor's bytes lie in the data buffer.
struct Extent {
  std::uint64_t begin;
  std::uint64_t end;
  const std::string* name;
};

class HeaderParser {
 public:
  HeaderParser(const std::string& origin, std::string_view buffer)
      : origin_(origin), buffer_(buffer) {}

  [[noreturn]] void fail(const std::string& message) const { throw FormatError(origin_, message); }
  [[noreturn]] void fail(const std::string& tensor, const std::string& message) const {
    fail("tensor " + single_quoted(tensor) + ": " + message);
  }

  void parse_metadata(const Json& j, File& out) const {
    if (!j.is_object()) {
      fail(std::string(kMetadataKey) + " is a JSON " + j.type_name() +
           ", expected an object of strings");
    }
    for (const auto& [key, value] : j.items()) {
      if (!value.is_string()) {
        fail(std::string(kMetadataKey) + " entry " + single_quoted(key) + " is a JSON " +
             value.type_name() + ", expected a string");
      }
      out.metadata.emplace(key, value.get<std::string>());
    }
  }

  // One tensor entry; its bytes are copied from the buffer and its extent recorded.
  void parse_tensor(const std::string& name, const Json& j, File& out) {
    if (!j.is_object()) {
      fail(name, std::string("entry is a JSON ") + j.type_name() +
                     ", expected an object with dtype, shape and data_offsets");
    }
    for (const auto& [key, value] : j.items()) {
      if (key != "dtype" && key != "shape" && key != "data_offsets") {
        fail(name,
             "unexpected key " + single_quoted(key) + " (allowed: dtype, shape, data_offsets)");
      }
    }
    for (const char* key : {"dtype", "shape", "data_offsets"}) {
      if (!j.contains(key)) fail(name, std::string("missing key '") + key + "'");
    }

    Tensor t;
    const Json& dtype = j.at("dtype");
    if (!dtype.is_string()) {
      fail(name, std::string("dtype is a JSON ") + dtype.type_name() + ", expected a string");
    }
    const auto parsed_dtype = dtype_from_name(dtype.get_ref<const std::string&>());
    if (!parsed_dtype) {
      fail(name, "unsupported dtype " + single_quoted(dtype.get_ref<const std::string&>()) +
                     " (supported: F32, F64, I32, I64, U8)");
    }
    t.dtype = *parsed_dtype;

    const Json& shape = j.at("shape");
    if (!shape.is_array()) {
      fail(name, std::string("shape is a JSON ") + shape.type_name() +
                     ", expected a list of non-negative integers");
    }
    for (const Json& d : shape) {
      const auto dim = non_negative(d);
      if (!dim || *dim > kInt64Max) {
        fail(name, "shape " + shape.dump() + " is not a list of non-negative integers");
      }
      t.shape.push_back(static_cast<std::int64_t>(*dim));
    }

    const Json& offsets = j.at("data_offsets");
    std::optional<std::uint64_t> begin;
    std::optional<std::uint64_t> end;
    if (offsets.is_array() && offsets.size() == 2) {
      begin = non_negative(offsets[0]);
      end = non_negative(offsets[1]);
    }
    if (!begin || !end) {
      fail(name, "data_offsets " + offsets.dump() + " is not a list of two non-negative integers");
    }
    if (*begin > *end) {
      fail(name, "data_offsets " + offsets_text(*begin, *end) + " has begin > end");
    }
    if (*end > buffer_.size()) {
      fail(name, "data_offsets " + offsets_text(*begin, *end) + " end beyond the data buffer of " +
                     std::to_string(buffer_.size()) + " bytes");
    }

    // Dimensions are non-negative here; no count means the product overflows int64.
    const auto count = element_count(t.shape);
    const auto expected_bytes =
        count ? checked_mul(static_cast<std::uint64_t>(*count), dtype_size(t.dtype)) : std::nullopt;
    if (!expected_bytes || *expected_bytes != *end - *begin) {
      fail(name,
           "data_offsets " + offsets_text(*begin, *end) + " span " + std::to_string(*end - *begin) +
               " bytes, but dtype " + std::string(dtype_name(t.dtype)) + " and shape " +
               shape_text(t.shape) + " need " +
               (expected_bytes ? std::to_string(*expected_bytes) : "more than 2^63") + " bytes");
    }

    const auto first = buffer_.begin() + static_cast<std::ptrdiff_t>(*begin);
    t.bytes.assign(first, first + static_cast<std::ptrdiff_t>(*end - *begin));
    const auto [it, inserted] = out.tensors.emplace(name, std::move(t));
    extents_.push_back({*begin, *end, &it->first});
  }

  // The tensors must cover the buffer exactly: no overlaps, gaps or trailing bytes.
  void check_coverage() {
    std::sort(extents_.begin(), extents_.end(), [](const Extent& a, const Extent& b) {
      return std::tie(a.begin, a.end, *a.name) < std::tie(b.begin, b.end, *b.name);
    });
    std::uint64_t covered = 0;
    const Extent* previous = nullptr;
    for (const Extent& e : extents_) {
      if (e.begin < covered) {
        fail("tensors " + single_quoted(*previous->name) + " (data_offsets " +
             offsets_text(previous->begin, previous->end) + ") and " + single_quoted(*e.name) +
             " (data_offsets " + offsets_text(e.begin, e.end) + ") overlap");
      }
      if (e.begin > covered) {
        fail("gap in the data buffer: bytes " + offsets_text(covered, e.begin) +
             " belong to no tensor (next tensor: " + single_quoted(*e.name) + ")");
      }
      covered = e.end;
      if (e.begin != e.end) previous = &e;  // the tensor holding the bytes before `covered`
    }
    if (covered != buffer_.size()) {
      fail(std::to_string(buffer_.size() - covered) +
           " trailing bytes in the data buffer after the last tensor (bytes " +
           offsets_text(covered, buffer_.size()) + " belong to no tensor)");
    }
  }

 private:
  // The value of a JSON integer >= 0; nullopt for anything else (floats,
  // negative numbers, numbers beyond uint64 which nlohmann reads as floats).
  static std::optional<std::uint64_t> non_negative(const Json& j) {
    if (j.is_number_unsigned()) return j.get<std::uint64_t>();
    if (j.is_number_integer() && j.get<std::int64_t>() == 0) return 0;  // "-0"
    return std::nullopt;
  }

  const std::string& origin_;
  std::string_view buffer_;
  std::vector<Extent> extents_;
};

// ---- writing ----

// Throws unless `s` is valid UTF-8 (as nlohmann's dump() would on output).
void check_utf8(const std::string& s, const std::string& what, const std::string& origin) {
  try {
    (void)Json(s).dump();
  } catch (const Json::type_error&) {
    throw FormatError(origin, what + " is not valid UTF-8");
  }
}

}  // namespace

FormatError::FormatError(std::string origin, std::string message)
    : std::runtime_error(compose(origin, message)),
      origin_(std::move(origin)),
      message_(std::move(message)) {}

std::string_view dtype_name(DType dtype) {
  switch (dtype) {
    case DType::kF32:
      return "F32";
    case DType::kF64:
      return "F64";
    case DType::kI32:
      return "I32";
    case DType::kI64:
      return "I64";
    case DType::kU8:
      return "U8";
  }
  throw std::invalid_argument("safetensors: invalid DType value");
}

std::size_t dtype_size(DType dtype) {
  switch (dtype) {
    case DType::kF32:
    case DType::kI32:
      return 4;
    case DType::kF64:
    case DType::kI64:
      return 8;
    case DType::kU8:
      return 1;
  }
  throw std::invalid_argument("safetensors: invalid DType value");
}

std::optional<DType> dtype_from_name(std::string_view name) {
  for (const DType d : {DType::kF32, DType::kF64, DType::kI32, DType::kI64, DType::kU8}) {
    if (dtype_name(d) == name) return d;
  }
  return std::nullopt;
}

std::int64_t Tensor::elements() const {
  const auto count = element_count(shape);
  if (!count) {
    throw std::invalid_argument("safetensors: shape " + shape_text(shape) +
                                " has a negative dimension or more elements than fit in int64");
  }
  return *count;
}

Tensor make_f32(std::vector<std::int64_t> shape, std::span<const float> values) {
  return make_tensor(DType::kF32, std::move(shape), values);
}

Tensor make_f64(std::vector<std::int64_t> shape, std::span<const double> values) {
  return make_tensor(DType::kF64, std::move(shape), values);
}

Tensor make_i32(std::vector<std::int64_t> shape, std::span<const std::int32_t> values) {
  return make_tensor(DType::kI32, std::move(shape), values);
}

std::vector<float> as_f32(const File& file, const std::string& name,
                          const std::vector<std::int64_t>& expected_shape) {
  const Tensor& t = checked_tensor(file, name, expected_shape);
  if (t.dtype == DType::kF32) return values_of<float>(t);
  if (t.dtype != DType::kF64) wrong_dtype(file, name, t.dtype, "F32 or F64");
  const std::vector<double> wide = values_of<double>(t);
  std::vector<float> out(wide.size());
  for (std::size_t i = 0; i < wide.size(); ++i) {
    const double v = wide[i];
    if (std::isfinite(v) && std::fabs(v) > static_cast<double>(std::numeric_limits<float>::max())) {
      char text[32];
      const auto end = std::to_chars(text, text + sizeof text, v).ptr;
      throw FormatError(file.origin, "tensor " + single_quoted(name) + " element " +
                                         std::to_string(i) + " (" + std::string(text, end) +
                                         ") is beyond the F32 range");
    }
    out[i] = static_cast<float>(v);
  }
  return out;
}

std::vector<double> as_f64(const File& file, const std::string& name,
                           const std::vector<std::int64_t>& expected_shape) {
  const Tensor& t = checked_tensor(file, name, expected_shape);
  if (t.dtype == DType::kF64) return values_of<double>(t);
  if (t.dtype != DType::kF32) wrong_dtype(file, name, t.dtype, "F32 or F64");
  const std::vector<float> narrow = values_of<float>(t);
  return std::vector<double>(narrow.begin(), narrow.end());
}

std::vector<std::int32_t> as_i32(const File& file, const std::string& name,
                                 const std::vector<std::int64_t>& expected_shape) {
  const Tensor& t = checked_tensor(file, name, expected_shape);
  if (t.dtype != DType::kI32) wrong_dtype(file, name, t.dtype, "I32");
  return values_of<std::int32_t>(t);
}

std::string serialize(const File& file, const std::string& origin_for_errors) {
  const std::string& origin = origin_for_errors;
  Json header = Json::object();  // std::map based: keys come out sorted
  std::uint64_t offset = 0;
  for (const auto& [name, t] : file.tensors) {
    if (name == kMetadataKey) {
      throw FormatError(origin, "a tensor may not be named " + single_quoted(kMetadataKey));
    }
    check_utf8(name, "tensor name " + single_quoted(name), origin);
    const auto count = element_count(t.shape);
    if (!count) {
      throw FormatError(origin, "tensor " + single_quoted(name) + ": shape " + shape_text(t.shape) +
                                    " has a negative dimension or too many elements");
    }
    const auto expected = checked_mul(static_cast<std::uint64_t>(*count), dtype_size(t.dtype));
    if (!expected || *expected != t.bytes.size()) {
      throw FormatError(origin, "tensor " + single_quoted(name) + " holds " +
                                    std::to_string(t.bytes.size()) + " bytes; dtype " +
                                    std::string(dtype_name(t.dtype)) + " and shape " +
                                    shape_text(t.shape) + " need " +
                                    (expected ? std::to_string(*expected) : "more than 2^64"));
    }
    const std::uint64_t end = offset + t.bytes.size();
    header[name] = {{"dtype", std::string(dtype_name(t.dtype))},
                    {"shape", t.shape},
                    {"data_offsets", {offset, end}}};
    offset = end;
  }
  if (!file.metadata.empty()) {
    Json metadata = Json::object();
    for (const auto& [key, value] : file.metadata) {
      check_utf8(key, std::string(kMetadataKey) + " key " + single_quoted(key), origin);
      check_utf8(value, std::string(kMetadataKey) + " value of " + single_quoted(key), origin);
      metadata[key] = value;
    }
    header[std::string(kMetadataKey)] = std::move(metadata);
  }

  std::string text = header.dump();
  text.append((8 - text.size() % 8) % 8, ' ');  // the data buffer starts 8-byte aligned

  std::string out;
  out.reserve(8 + text.size() + offset);
  const std::uint64_t length = text.size();
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((length >> (8 * i)) & 0xffu));
  out += text;
  for (const auto& [name, t] : file.tensors) {
    out.append(reinterpret_cast<const char*>(t.bytes.data()), t.bytes.size());
  }
  return out;
}

File parse(std::string_view bytes, const std::string& origin) {
  if (bytes.size() < 8) {
    throw FormatError(origin, "file is " + std::to_string(bytes.size()) +
                                  " bytes long, shorter than the 8-byte header length field");
  }
  std::uint64_t length = 0;
  for (int i = 7; i >= 0; --i) {
    length = (length << 8) | static_cast<unsigned char>(bytes[static_cast<std::size_t>(i)]);
  }
  const std::size_t available = bytes.size() - 8;
  if (length > kMaxHeaderBytes) {
    throw FormatError(origin, "header length " + std::to_string(length) + " is absurd (limit " +
                                  std::to_string(kMaxHeaderBytes) +
                                  " bytes); not a safetensors file?");
  }
  if (length > available) {
    throw FormatError(origin, "header length " + std::to_string(length) + " exceeds the " +
                                  std::to_string(available) + " bytes after the length field");
  }
  const std::string_view text = bytes.substr(8, static_cast<std::size_t>(length));
  const std::string_view buffer = bytes.substr(8 + static_cast<std::size_t>(length));

  if (text.empty() || text.front() != '{') {
    throw FormatError(origin, "header does not start with '{'; expected a JSON object");
  }
  HeaderChecker checker(origin);
  Json header;
  try {
    header = Json::parse(text, std::ref(checker));
  } catch (const Json::parse_error& e) {
    throw FormatError(origin, std::string("header is not valid JSON: ") + e.what());
  } catch (const Json::exception& e) {
    // out_of_range 406: a number beyond double's range (found by model_fuzzer).
    throw FormatError(origin, std::string("header is not readable JSON: ") +
                                  (e.id == 406 ? "a number beyond the range of a double" : e.what()));
  }
  if (!header.is_object()) {
    throw FormatError(
        origin, std::string("header is a JSON ") + header.type_name() + ", expected an object");
  }

  File out;
  out.origin = origin;
  HeaderParser parser(origin, buffer);
  for (const auto& [key, value] : header.items()) {
    if (key == kMetadataKey) {
      parser.parse_metadata(value, out);
    } else {
      parser.parse_tensor(key, value, out);
    }
  }
  parser.check_coverage();
  return out;
}

std::string read_bytes(const std::string& path) {
  const auto fail = [&](const std::string& what, int error) {
    return FormatError(path, "cannot read safetensors file: " + what + ": " +
                                 std::generic_category().message(error));
  };
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    throw fail("open", error);
  }
  std::string bytes;
  try {
    struct stat info {};
    if (::fstat(fd, &info) != 0) {
      const int error = errno;
      throw fail("stat", error);
    }
    if (S_ISDIR(info.st_mode)) throw fail("open", EISDIR);
    const auto too_large = [&] {
      return FormatError(path, "cannot read safetensors file: larger than " +
                                   std::to_string(kMaxFileBytes) + " bytes, the most a model file may hold");
    };
    if (info.st_size > 0 && static_cast<std::uint64_t>(info.st_size) > kMaxFileBytes) throw too_large();
    if (info.st_size > 0) bytes.reserve(static_cast<std::size_t>(info.st_size));
    char chunk[1 << 16];
    for (;;) {
      if (bytes.size() > kMaxFileBytes) throw too_large();
      const ssize_t n = ::read(fd, chunk, sizeof chunk);
      if (n < 0) {
        const int error = errno;
        if (error == EINTR) continue;
        throw fail("read", error);
      }
      if (n == 0) break;
      bytes.append(chunk, static_cast<std::size_t>(n));
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return bytes;
}

File read_file(const std::string& path) { return parse(read_bytes(path), path); }

void write_file(const std::string& path, const File& file) {
  const std::string bytes = serialize(file, path);
  try {
    datalog::write_file_atomically(path, bytes);
  } catch (const datalog::AtomicWriteError& e) {
    throw FormatError(path, std::string("cannot write safetensors file: ") + e.what());
  }
}

}  // namespace hadynet::trainer::safetensors
