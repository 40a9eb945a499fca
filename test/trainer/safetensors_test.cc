// safetensors reader/writer: exact round trips, deterministic and aligned
// output, a hand-built reference file, every malformed input rejected with a
// FormatError naming the file and the problem, atomic file writing.
// All comparisons are exact (bytes); no tolerances are involved.
#include "trainer/safetensors.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace hadynet::trainer::safetensors {
namespace {

const std::string kOrigin = "model.safetensors";

// The bytes of a safetensors file: 8-byte LE length of `header`, `header`, `buffer`.
std::string file_bytes(const std::string& header, const std::string& buffer = "") {
  std::string out;
  const std::uint64_t n = header.size();
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((n >> (8 * i)) & 0xffu));
  return out + header + buffer;
}

// The header length field of a file.
std::uint64_t header_length(const std::string& bytes) {
  std::uint64_t n = 0;
  for (int i = 7; i >= 0; --i) n = (n << 8) | static_cast<unsigned char>(bytes[i]);
  return n;
}

Tensor make_i64(std::vector<std::int64_t> shape, const std::vector<std::int64_t>& values) {
  Tensor t;
  t.dtype = DType::kI64;
  t.shape = std::move(shape);
  t.bytes.resize(values.size() * 8);
  std::memcpy(t.bytes.data(), values.data(), t.bytes.size());
  return t;
}

Tensor make_u8(std::vector<std::int64_t> shape, const std::vector<std::uint8_t>& values) {
  Tensor t;
  t.dtype = DType::kU8;
  t.shape = std::move(shape);
  t.bytes = values;
  return t;
}

// Several tensors of every dtype, with awkward values (signed zeros, NaN with
// a payload, infinities, denormals, extreme integers) and metadata.
File sample_file() {
  File f;
  f.metadata = {{"format", "pt"}, {"note", "x\ty \"quoted\" \xc3\xa9"}, {"empty", ""}};
  const float nan_payload = std::bit_cast<float>(0x7fc01234u);
  const std::vector<float> f32{1.0f,
                               -0.0f,
                               nan_payload,
                               std::numeric_limits<float>::infinity(),
                               std::numeric_limits<float>::denorm_min(),
                               3.14159274f};
  f.tensors["enc.weight"] = make_f32({2, 3}, f32);
  f.tensors["enc.bias"] = make_f32({3}, std::vector<float>{0.5f, -2.0f, 1e-30f});
  const std::vector<double> f64{-std::numeric_limits<double>::infinity(),
                                std::bit_cast<double>(0x7ff8000000000abcull), 1.0 / 3.0,
                                std::numeric_limits<double>::denorm_min()};
  f.tensors["pb"] = make_f64({2, 2}, f64);
  f.tensors["pb_alt"] = make_f64({1, 1, 1}, std::vector<double>{-1e300});
  f.tensors["ids"] = make_i32({4}, std::vector<std::int32_t>{0, -1, 2147483647, -2147483647 - 1});
  f.tensors["ids2"] = make_i32({2, 1}, std::vector<std::int32_t>{7, -7});
  f.tensors["i64"] = make_i64({2}, {std::numeric_limits<std::int64_t>::min(), 42});
  f.tensors["i64b"] = make_i64({1, 3}, {std::numeric_limits<std::int64_t>::max(), -1, 0});
  f.tensors["mask"] = make_u8({5}, {0, 1, 255, 7, 128});
  f.tensors["mask2"] = make_u8({1, 3}, {9, 8, 7});
  return f;
}

void expect_same(const File& a, const File& b) {
  EXPECT_EQ(a.metadata, b.metadata);
  ASSERT_EQ(a.tensors.size(), b.tensors.size());
  for (const auto& [name, t] : a.tensors) {
    const auto it = b.tensors.find(name);
    ASSERT_NE(it, b.tensors.end()) << name;
    EXPECT_EQ(it->second.dtype, t.dtype) << name;
    EXPECT_EQ(it->second.shape, t.shape) << name;
    EXPECT_EQ(it->second.bytes, t.bytes) << name;  // bit-exact
  }
}

// The FormatError parse() throws for `bytes` (fails the test if none).
FormatError parse_error(const std::string& bytes) {
  try {
    parse(bytes, kOrigin);
  } catch (const FormatError& e) {
    return e;
  }
  ADD_FAILURE() << "parse() accepted a malformed file";
  return FormatError("", "");
}

// parse() must reject `bytes` with a message starting with the origin and
// holding every fragment.
void expect_rejected(const std::string& bytes, std::initializer_list<std::string> fragments) {
  const FormatError e = parse_error(bytes);
  const std::string what = e.what();
  EXPECT_EQ(e.origin(), kOrigin);
  EXPECT_EQ(what.rfind(kOrigin + ": ", 0), 0u) << what;
  for (const std::string& fragment : fragments) {
    EXPECT_NE(what.find(fragment), std::string::npos)
        << "message: " << what << "\nmissing fragment: " << fragment;
  }
}

// ---- formats and round trips ----

TEST(Safetensors, DTypeNamesAndSizes) {
  EXPECT_EQ(dtype_name(DType::kF32), "F32");
  EXPECT_EQ(dtype_name(DType::kF64), "F64");
  EXPECT_EQ(dtype_name(DType::kI32), "I32");
  EXPECT_EQ(dtype_name(DType::kI64), "I64");
  EXPECT_EQ(dtype_name(DType::kU8), "U8");
  EXPECT_EQ(dtype_size(DType::kF32), 4u);
  EXPECT_EQ(dtype_size(DType::kF64), 8u);
  EXPECT_EQ(dtype_size(DType::kI32), 4u);
  EXPECT_EQ(dtype_size(DType::kI64), 8u);
  EXPECT_EQ(dtype_size(DType::kU8), 1u);
  for (const DType d : {DType::kF32, DType::kF64, DType::kI32, DType::kI64, DType::kU8}) {
    EXPECT_EQ(dtype_from_name(dtype_name(d)), d);
  }
  EXPECT_EQ(dtype_from_name("f32"), std::nullopt);
  EXPECT_EQ(dtype_from_name("F16"), std::nullopt);
}

TEST(Safetensors, RoundTripIsBitExact) {
  const File f = sample_file();
  const File back = parse(serialize(f), kOrigin);
  expect_same(f, back);
  EXPECT_EQ(back.origin, kOrigin);
}

TEST(Safetensors, ScalarAndZeroSizeTensors) {
  File f;
  f.tensors["scalar"] = make_f64({}, std::vector<double>{2.5});
  f.tensors["empty"] = make_f32({0}, std::span<const float>());
  f.tensors["empty2d"] = make_i32({3, 0}, std::span<const std::int32_t>());
  f.tensors["zz_empty"] = make_u8({0, 7}, {});
  EXPECT_EQ(f.tensors["scalar"].elements(), 1);
  EXPECT_EQ(f.tensors["empty2d"].elements(), 0);
  const File back = parse(serialize(f), kOrigin);
  expect_same(f, back);
  EXPECT_EQ(as_f64(back, "scalar", {}), std::vector<double>{2.5});
  EXPECT_TRUE(as_f32(back, "empty", {0}).empty());
  EXPECT_TRUE(as_i32(back, "empty2d", {3, 0}).empty());
}

TEST(Safetensors, EmptyFileRoundTrips) {
  const std::string bytes = serialize(File{});
  EXPECT_EQ(bytes, file_bytes("{}      "));
  const File back = parse(bytes, kOrigin);
  EXPECT_TRUE(back.tensors.empty());
  EXPECT_TRUE(back.metadata.empty());
}

TEST(Safetensors, SerializeIsDeterministic) {
  const File f = sample_file();
  EXPECT_EQ(serialize(f), serialize(f));
  // Re-serializing what was read gives the same bytes.
  EXPECT_EQ(serialize(parse(serialize(f), kOrigin)), serialize(f));
}

// Exact bytes: sorted keys, compact JSON, tensors by name, back to back.
TEST(Safetensors, SerializeExactLayout) {
  File f;
  f.metadata["k"] = "v";
  f.tensors["b"] = make_f32({2}, std::vector<float>{1.0f, 2.0f});
  f.tensors["a"] = make_u8({3}, {1, 2, 3});
  const std::string json = R"({"__metadata__":{"k":"v"},)"
                           R"("a":{"data_offsets":[0,3],"dtype":"U8","shape":[3]},)"
                           R"("b":{"data_offsets":[3,11],"dtype":"F32","shape":[2]}})";
  std::string header = json;
  header.append((8 - json.size() % 8) % 8, ' ');
  std::string buffer = "\x01\x02\x03";
  buffer += std::string("\x00\x00\x80\x3f\x00\x00\x00\x40", 8);  // 1.0f, 2.0f little-endian
  EXPECT_EQ(serialize(f), file_bytes(header, buffer));
}

TEST(Safetensors, HeaderIsPaddedToEightBytes) {
  // Names of every length mod 8 exercise every padding amount.
  for (int length = 1; length <= 16; ++length) {
    File f;
    f.tensors[std::string(static_cast<std::size_t>(length), 'n')] =
        make_f32({1}, std::vector<float>{1.0f});
    const std::string bytes = serialize(f);
    const std::uint64_t n = header_length(bytes);
    EXPECT_EQ(n % 8, 0u) << length;
    EXPECT_EQ((8 + n) % 8, 0u) << length;  // the data buffer starts aligned
    const std::string header = bytes.substr(8, n);
    const std::size_t close = header.rfind('}');
    ASSERT_NE(close, std::string::npos);
    EXPECT_LT(header.size() - close - 1, 8u);
    EXPECT_EQ(header.find_first_not_of(' ', close + 1), std::string::npos) << length;
    EXPECT_EQ(bytes.size(), 8 + n + 4);
    EXPECT_NO_THROW(parse(bytes, kOrigin));
  }
}

// The bytes the Python reference writes for {"a": tensor([1.0, 2.0])}
// (safetensors.torch.save_file), built by hand.
TEST(Safetensors, ReadsReferenceFile) {
  const std::string json = R"({"a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]}})";
  ASSERT_EQ(json.size(), 54u);  // the reference writer pads with 2 spaces to 56
  std::string bytes(8, '\0');
  bytes[0] = 56;
  bytes += json + "  ";
  bytes += std::string("\x00\x00\x80\x3f\x00\x00\x00\x40", 8);
  const File f = parse(bytes, kOrigin);
  ASSERT_EQ(f.tensors.size(), 1u);
  EXPECT_TRUE(f.metadata.empty());
  const Tensor& a = f.tensors.at("a");
  EXPECT_EQ(a.dtype, DType::kF32);
  EXPECT_EQ(a.shape, std::vector<std::int64_t>{2});
  EXPECT_EQ(as_f32(f, "a", {2}), (std::vector<float>{1.0f, 2.0f}));
  // Our writer produces the very same bytes.
  EXPECT_EQ(serialize(f).size(), bytes.size());
  EXPECT_EQ(parse(serialize(f), kOrigin).tensors.at("a"), a);

  // Writers that do not pad are read too.
  bytes[0] = 54;
  bytes.erase(8 + 54, 2);
  EXPECT_EQ(parse(bytes, kOrigin).tensors.at("a"), a);

  // The same with metadata and space padding, as save_file(..., metadata=) writes.
  const std::string json2 =
      R"({"__metadata__":{"format":"pt"},"a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]}})";
  std::string header2 = json2 + std::string((8 - json2.size() % 8) % 8, ' ');
  const File g =
      parse(file_bytes(header2, std::string("\x00\x00\x80\x3f\x00\x00\x00\x40", 8)), kOrigin);
  EXPECT_EQ(g.metadata.at("format"), "pt");
  EXPECT_EQ(as_f64(g, "a", {2}), (std::vector<double>{1.0, 2.0}));
}

// Tensors may be stored in any order in the buffer, and the header need not
// be sorted, as long as the buffer is covered exactly.
TEST(Safetensors, ReadsUnsortedLayout) {
  const std::string header = R"({"z":{"dtype":"U8","shape":[1],"data_offsets":[0,1]},)"
                             R"("e":{"dtype":"U8","shape":[0],"data_offsets":[1,1]},)"
                             R"("a":{"shape":[2],"data_offsets":[1,3],"dtype":"U8"}})";
  const File f = parse(file_bytes(header, "xyz"), kOrigin);
  EXPECT_EQ(f.tensors.at("z").bytes, std::vector<std::uint8_t>{'x'});
  EXPECT_EQ(f.tensors.at("a").bytes, (std::vector<std::uint8_t>{'y', 'z'}));
  EXPECT_TRUE(f.tensors.at("e").bytes.empty());
}

// ---- typed access ----

TEST(Safetensors, TypedAccessConvertsFloats) {
  File f;
  f.origin = kOrigin;
  f.tensors["w32"] = make_f32({2}, std::vector<float>{0.1f, -3.0f});
  f.tensors["w64"] = make_f64({2}, std::vector<double>{0.1, -3.0});
  EXPECT_EQ(as_f32(f, "w32", {2}), (std::vector<float>{0.1f, -3.0f}));
  EXPECT_EQ(as_f32(f, "w64", {2}), (std::vector<float>{0.1f, -3.0f}));  // rounded to nearest
  EXPECT_EQ(as_f64(f, "w32", {2}), (std::vector<double>{double{0.1f}, -3.0}));  // exact
  EXPECT_EQ(as_f64(f, "w64", {2}), (std::vector<double>{0.1, -3.0}));
}

TEST(Safetensors, TypedAccessErrorsNameTensor) {
  File f;
  f.origin = kOrigin;
  f.tensors["enc.weight"] = make_f32({128, 44}, std::vector<float>(128 * 44));
  f.tensors["ids"] = make_i32({1}, std::vector<std::int32_t>{1});
  f.tensors["big"] = make_f64({1}, std::vector<double>{1e300});
  try {
    as_f32(f, "enc.weight", {128, 45});
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_STREQ(e.what(),
                 "model.safetensors: tensor 'enc.weight' has shape [128, 44], expected [128, 45]");
  }
  try {
    as_f64(f, "enc.bias", {128});
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_EQ(std::string(e.what()), "model.safetensors: tensor 'enc.bias' is missing");
  }
  try {
    as_f32(f, "ids", {1});
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_EQ(std::string(e.what()),
              "model.safetensors: tensor 'ids' has dtype I32, expected F32 or F64");
  }
  try {
    as_i32(f, "enc.weight", {128, 44});
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("'enc.weight' has dtype F32, expected I32"),
              std::string::npos);
  }
  try {
    as_f32(f, "big", {1});
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("'big' element 0"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("F32 range"), std::string::npos) << e.what();
  }
  EXPECT_EQ(as_f64(f, "big", {1}), std::vector<double>{1e300});
}

TEST(Safetensors, TypedAccessChecksBytesOfHandBuiltTensor) {
  File f;
  f.tensors["t"] = make_f32({2}, std::vector<float>{1.0f, 2.0f});
  f.tensors["t"].bytes.pop_back();
  EXPECT_THROW(as_f32(f, "t", {2}), FormatError);
}

TEST(Safetensors, MakeChecksShape) {
  const std::vector<float> three{1.0f, 2.0f, 3.0f};
  EXPECT_THROW(make_f32({2, 2}, three), std::invalid_argument);
  EXPECT_THROW(make_f32({-1, -3}, three), std::invalid_argument);
  EXPECT_THROW(make_f64({}, std::vector<double>{}), std::invalid_argument);  // rank 0 = 1 value
  EXPECT_THROW(make_i32({2}, std::vector<std::int32_t>{1}), std::invalid_argument);
  const Tensor t = make_f32({1, 3}, three);
  EXPECT_EQ(t.bytes.size(), 12u);
  EXPECT_EQ(t.elements(), 3);
  Tensor bad;
  bad.shape = {-2};
  EXPECT_THROW(bad.elements(), std::invalid_argument);
  bad.shape = {std::int64_t{1} << 40, std::int64_t{1} << 40};
  EXPECT_THROW(bad.elements(), std::invalid_argument);
}

// ---- writer errors ----

TEST(Safetensors, SerializeRejectsInconsistentFiles) {
  const auto message = [](const File& f) -> std::string {
    try {
      serialize(f, kOrigin);
    } catch (const FormatError& e) {
      return e.what();
    }
    return "(no error)";
  };
  File f;
  f.tensors["__metadata__"] = make_f32({1}, std::vector<float>{1.0f});
  EXPECT_NE(message(f).find("may not be named '__metadata__'"), std::string::npos) << message(f);

  f.tensors.clear();
  f.tensors["w"] = make_f32({2}, std::vector<float>{1.0f, 2.0f});
  f.tensors["w"].shape = {3};
  EXPECT_NE(message(f).find("model.safetensors: tensor 'w' holds 8 bytes"), std::string::npos)
      << message(f);

  f.tensors["w"].shape = {-2};
  EXPECT_NE(message(f).find("tensor 'w': shape [-2]"), std::string::npos) << message(f);

  f.tensors.clear();
  f.tensors["bad\xff"] = make_f32({1}, std::vector<float>{1.0f});
  EXPECT_NE(message(f).find("not valid UTF-8"), std::string::npos) << message(f);

  f.tensors.clear();
  f.metadata["k"] = "\xc3";
  EXPECT_NE(message(f).find("value of 'k' is not valid UTF-8"), std::string::npos) << message(f);
}

// ---- reader errors ----

const std::string kGood = R"({"a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]}})";
const std::string kEight(8, '\x01');

// A header holding one tensor "a" with the given entry JSON.
std::string with_entry(const std::string& entry) { return R"({"a":)" + entry + "}"; }

TEST(SafetensorsReject, ShortFile) {
  expect_rejected("", {"0 bytes", "8-byte header length"});
  expect_rejected(std::string(7, '\0'), {"7 bytes", "8-byte header length"});
}

TEST(SafetensorsReject, HeaderLengthBeyondFile) {
  std::string bytes = file_bytes(kGood, kEight);
  bytes[0] = static_cast<char>(bytes[0] + 100);  // 154 > 62 available
  expect_rejected(bytes, {"header length 154", "exceeds the 62 bytes"});
  std::string empty_header(8, '\0');
  expect_rejected(empty_header, {"does not start with '{'"});
  std::string one(8, '\0');
  one[0] = 1;
  expect_rejected(one, {"header length 1 exceeds the 0 bytes"});
}

TEST(SafetensorsReject, AbsurdHeaderLength) {
  std::string bytes = file_bytes(kGood, kEight);
  for (int i = 0; i < 8; ++i) bytes[static_cast<std::size_t>(i)] = '\xff';
  expect_rejected(bytes, {"header length 18446744073709551615", "absurd"});
  const std::uint64_t just_over = 100'000'001;
  for (int i = 0; i < 8; ++i) {
    bytes[static_cast<std::size_t>(i)] = static_cast<char>((just_over >> (8 * i)) & 0xffu);
  }
  expect_rejected(bytes, {"header length 100000001", "absurd"});
}

TEST(SafetensorsReject, HeaderNotJsonObject) {
  expect_rejected(file_bytes(R"({"a":)"), {"not valid JSON"});
  expect_rejected(file_bytes(R"({"a":1} x)"), {"not valid JSON"});
  expect_rejected(file_bytes(R"({"a":1}})"), {"not valid JSON"});
  expect_rejected(file_bytes("{\"a\xff\":1}"), {"not valid JSON"});  // bad UTF-8
  expect_rejected(file_bytes(R"([1, 2])"), {"does not start with '{'"});
  expect_rejected(file_bytes(R"("text")"), {"does not start with '{'"});
  expect_rejected(file_bytes(R"( {})"), {"does not start with '{'"});
  expect_rejected(file_bytes("{} /* c */"), {"not valid JSON"});
}

TEST(SafetensorsReject, EntryNotObject) {
  expect_rejected(file_bytes(with_entry("5")), {"tensor 'a'", "entry is a JSON number"});
  expect_rejected(file_bytes(with_entry("[]")), {"tensor 'a'", "entry is a JSON array"});
}

TEST(SafetensorsReject, MissingOrExtraKeys) {
  expect_rejected(file_bytes(with_entry(R"({"dtype":"F32","shape":[2]})"), kEight),
                  {"tensor 'a'", "missing key 'data_offsets'"});
  expect_rejected(file_bytes(with_entry(R"({"dtype":"F32","data_offsets":[0,8]})"), kEight),
                  {"tensor 'a'", "missing key 'shape'"});
  expect_rejected(file_bytes(with_entry(R"({"shape":[2],"data_offsets":[0,8]})"), kEight),
                  {"tensor 'a'", "missing key 'dtype'"});
  expect_rejected(
      file_bytes(with_entry(R"({"dtype":"F32","shape":[2],"data_offsets":[0,8],"x":1})"), kEight),
      {"tensor 'a'", "unexpected key 'x'"});
}

TEST(SafetensorsReject, UnknownDtype) {
  for (const std::string dtype : {"\"F16\"", "\"f32\"", "\"BF16\"", "\"\"", "32", "null"}) {
    const std::string entry = R"({"dtype":)" + dtype + R"(,"shape":[2],"data_offsets":[0,8]})";
    expect_rejected(file_bytes(with_entry(entry), kEight), {"tensor 'a'", "dtype"});
  }
  expect_rejected(
      file_bytes(with_entry(R"({"dtype":"F16","shape":[4],"data_offsets":[0,8]})"), kEight),
      {"tensor 'a'", "unsupported dtype 'F16'"});
}

TEST(SafetensorsReject, BadShape) {
  for (const std::string shape :
       {"2", "\"2\"", "[-2]", "[2.0]", "[2, \"1\"]", "[[2]]", "[true]", "null", "[1e2]",
        "[9223372036854775808]", "[99999999999999999999]"}) {
    const std::string entry = R"({"dtype":"F32","shape":)" + shape + R"(,"data_offsets":[0,8]})";
    expect_rejected(file_bytes(with_entry(entry), kEight), {"tensor 'a'", "shape"});
  }
  expect_rejected(
      file_bytes(with_entry(R"({"dtype":"F32","shape":[-2],"data_offsets":[0,8]})"), kEight),
      {"tensor 'a'", "shape [-2] is not a list of non-negative integers"});
}

TEST(SafetensorsReject, BadDataOffsets) {
  for (const std::string offsets :
       {"8", "[8]", "[0,4,8]", "[0.0,8]", "[0,8.0]", "[-1,8]", "[\"0\",8]", "null", "{}", "[]"}) {
    const std::string entry = R"({"dtype":"F32","shape":[2],"data_offsets":)" + offsets + "}";
    expect_rejected(file_bytes(with_entry(entry), kEight),
                    {"tensor 'a'", "data_offsets", "not a list of two non-negative integers"});
  }
  expect_rejected(
      file_bytes(with_entry(R"({"dtype":"F32","shape":[2],"data_offsets":[8,0]})"), kEight),
      {"tensor 'a'", "data_offsets [8, 0] has begin > end"});
}

TEST(SafetensorsReject, EndBeyondBuffer) {
  expect_rejected(
      file_bytes(with_entry(R"({"dtype":"F32","shape":[2],"data_offsets":[0,8]})"), "1234"),
      {"tensor 'a'", "data_offsets [0, 8]", "beyond the data buffer of 4 bytes"});
  expect_rejected(file_bytes(with_entry(
                      R"({"dtype":"F32","shape":[2],"data_offsets":[0,18446744073709551615]})")),
                  {"tensor 'a'", "beyond the data buffer"});
}

TEST(SafetensorsReject, ByteLengthMismatch) {
  expect_rejected(
      file_bytes(with_entry(R"({"dtype":"F64","shape":[2],"data_offsets":[0,8]})"), kEight),
      {"tensor 'a'", "data_offsets [0, 8] span 8 bytes", "F64", "shape [2] need 16 bytes"});
  expect_rejected(
      file_bytes(with_entry(R"({"dtype":"U8","shape":[],"data_offsets":[0,8]})"), kEight),
      {"tensor 'a'", "shape [] need 1 bytes"});
  // Products that overflow 64 bits must not wrap around to a matching count.
  expect_rejected(file_bytes(with_entry(R"({"dtype":"U8","shape":[4294967296,4294967296],)"
                                        R"("data_offsets":[0,0]})")),
                  {"tensor 'a'", "more than 2^63"});
  expect_rejected(file_bytes(with_entry(R"({"dtype":"F64","shape":[2305843009213693952],)"
                                        R"("data_offsets":[0,0]})")),
                  {"tensor 'a'", "span 0 bytes"});
  expect_rejected(file_bytes(with_entry(R"({"dtype":"U8","shape":[0,9223372036854775807,2],)"
                                        R"("data_offsets":[0,8]})"),
                             kEight),
                  {"tensor 'a'", "need 0 bytes"});
}

TEST(SafetensorsReject, OverlappingTensors) {
  const std::string header = R"({"a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]},)"
                             R"("b":{"dtype":"F32","shape":[2],"data_offsets":[4,12]}})";
  expect_rejected(file_bytes(header, "123456789012"),
                  {"'a' (data_offsets [0, 8])", "'b' (data_offsets [4, 12])", "overlap"});
  const std::string same = R"({"a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]},)"
                           R"("b":{"dtype":"U8","shape":[8],"data_offsets":[0,8]}})";
  expect_rejected(file_bytes(same, kEight), {"'a'", "'b'", "overlap"});
  const std::string empty_inside = R"({"a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]},)"
                                   R"("e":{"dtype":"F32","shape":[0],"data_offsets":[4,4]}})";
  expect_rejected(file_bytes(empty_inside, kEight), {"'a'", "'e'", "overlap"});
}

TEST(SafetensorsReject, GapsAndTrailingBytes) {
  const std::string gap = R"({"a":{"dtype":"F32","shape":[1],"data_offsets":[0,4]},)"
                          R"("b":{"dtype":"F32","shape":[1],"data_offsets":[8,12]}})";
  expect_rejected(file_bytes(gap, "123456789012"), {"gap", "bytes [4, 8]", "'b'"});
  const std::string leading = R"({"a":{"dtype":"F32","shape":[1],"data_offsets":[4,8]}})";
  expect_rejected(file_bytes(leading, kEight), {"gap", "bytes [0, 4]", "'a'"});
  const std::string trailing = R"({"a":{"dtype":"F32","shape":[1],"data_offsets":[0,4]}})";
  expect_rejected(file_bytes(trailing, kEight), {"4 trailing bytes", "[4, 8]"});
  expect_rejected(file_bytes("{}", "x"), {"1 trailing bytes"});
}

TEST(SafetensorsReject, BadMetadata) {
  const auto with_metadata = [](const std::string& metadata) {
    return file_bytes(R"({"__metadata__":)" + metadata + "}");
  };
  expect_rejected(with_metadata("[]"), {"__metadata__ is a JSON array"});
  expect_rejected(with_metadata("\"x\""), {"__metadata__ is a JSON string"});
  expect_rejected(with_metadata("null"), {"__metadata__ is a JSON null"});
  expect_rejected(with_metadata(R"({"k":1})"), {"__metadata__ entry 'k' is a JSON number"});
  expect_rejected(with_metadata(R"({"k":null})"), {"__metadata__ entry 'k' is a JSON null"});
  expect_rejected(with_metadata(R"({"k":{"x":"y"}})"), {"__metadata__ entry 'k'"});
  EXPECT_EQ(parse(with_metadata("{}"), kOrigin).metadata.size(), 0u);
}

TEST(SafetensorsReject, DuplicateKeys) {
  const std::string entry = R"({"dtype":"F32","shape":[2],"data_offsets":[0,8]})";
  expect_rejected(file_bytes(R"({"a":)" + entry + R"(,"a":)" + entry + "}", kEight),
                  {"duplicate key 'a'"});
  expect_rejected(
      file_bytes(with_entry(R"({"dtype":"F32","dtype":"F32","shape":[2],"data_offsets":[0,8]})"),
                 kEight),
      {"duplicate key 'dtype'", "inside 'a'"});
  expect_rejected(file_bytes(R"({"__metadata__":{"k":"1","k":"2"}})"),
                  {"duplicate key 'k'", "inside '__metadata__'"});
  expect_rejected(file_bytes(R"({"__metadata__":{},"__metadata__":{}})"),
                  {"duplicate key '__metadata__'"});
  // The same key in different objects is fine.
  EXPECT_NO_THROW(
      parse(file_bytes(R"({"__metadata__":{"a":"x"},"a":)" + entry + "}", kEight), kOrigin));
}

TEST(SafetensorsReject, DeepNesting) {
  const std::string deep = R"({"__metadata__":)" + std::string(100000, '[') + "}";
  expect_rejected(file_bytes(deep), {"nests deeper than 32 levels"});
  std::string objects = "{";
  for (int i = 0; i < 40; ++i) objects += R"("k":{)";
  objects += std::string(41, '}');
  expect_rejected(file_bytes(objects), {"nests deeper than 32 levels"});
}

// Every proper prefix of a valid file is invalid and must be rejected cleanly.
TEST(SafetensorsReject, EveryTruncationIsRejected) {
  const std::string bytes = serialize(sample_file());
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_THROW(parse(std::string_view(bytes).substr(0, n), kOrigin), FormatError) << n;
  }
}

// Corrupting any one byte of the length field or header gives a FormatError or
// a file that is still consistent (never a crash or other exception; run
// under ASan/UBSan in the debug preset).
TEST(SafetensorsReject, CorruptedHeaderBytesAreHandled) {
  const std::string good = serialize(sample_file());
  const std::size_t header_end = 8 + static_cast<std::size_t>(header_length(good));
  for (std::size_t i = 0; i < header_end; ++i) {
    for (const int value : {0x00, 0x01, 0x22, 0x2c, 0x30, 0x39, 0x5b, 0x7b, 0x7d, 0xff}) {
      std::string bytes = good;
      bytes[i] = static_cast<char>(value);
      try {
        const File f = parse(bytes, kOrigin);
        EXPECT_NO_THROW(parse(serialize(f), kOrigin)) << i;
      } catch (const FormatError&) {
      }
    }
  }
}

// ---- files ----

class SafetensorsFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "safetensors_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    folder_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::vector<std::string> folder_entries() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(folder_)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  static std::string contents(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
  }

  std::filesystem::path folder_;
};

TEST_F(SafetensorsFiles, WriteThenRead) {
  const std::string path = (folder_ / "model.safetensors").string();
  const File f = sample_file();
  write_file(path, f);
  EXPECT_EQ(folder_entries(), std::vector<std::string>{"model.safetensors"});
  EXPECT_EQ(contents(path), serialize(f));
  const File back = read_file(path);
  expect_same(f, back);
  EXPECT_EQ(back.origin, path);
}

// Writing over a larger file replaces it whole (no tail of the old file).
TEST_F(SafetensorsFiles, ReplacesExistingFileAndLeavesNoTemporary) {
  const std::string path = (folder_ / "model.safetensors").string();
  File big;
  big.tensors["w"] = make_f64({1000}, std::vector<double>(1000, 1.5));
  write_file(path, big);
  File small;
  small.tensors["v"] = make_f32({2}, std::vector<float>{1.0f, 2.0f});
  write_file(path, small);
  EXPECT_EQ(folder_entries(), std::vector<std::string>{"model.safetensors"});
  EXPECT_EQ(contents(path), serialize(small));
  expect_same(read_file(path), small);
}

// A file the writer rejects changes nothing on disk.
TEST_F(SafetensorsFiles, FailedWriteKeepsOldFile) {
  const std::string path = (folder_ / "model.safetensors").string();
  const File f = sample_file();
  write_file(path, f);
  File bad;
  bad.tensors["w"] = make_f32({2}, std::vector<float>{1.0f, 2.0f});
  bad.tensors["w"].bytes.push_back(0);
  try {
    write_file(path, bad);
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.origin(), path);
  }
  EXPECT_EQ(folder_entries(), std::vector<std::string>{"model.safetensors"});
  EXPECT_EQ(contents(path), serialize(f));
}

TEST_F(SafetensorsFiles, WriteIntoMissingFolderNamesPath) {
  const std::string path = (folder_ / "no" / "such" / "model.safetensors").string();
  try {
    write_file(path, sample_file());
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.origin(), path);
    EXPECT_EQ(std::string(e.what()).rfind(path + ": cannot write", 0), 0u) << e.what();
  }
  EXPECT_TRUE(folder_entries().empty());
}

TEST_F(SafetensorsFiles, ReadMissingFileNamesPath) {
  const std::string path = (folder_ / "missing.safetensors").string();
  try {
    read_file(path);
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.origin(), path);
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": cannot read", 0), 0u) << what;
    EXPECT_NE(what.find("No such file"), std::string::npos) << what;
  }
  EXPECT_THROW(read_file(folder_.string()), FormatError);  // a directory
}

TEST_F(SafetensorsFiles, ParseErrorsOfReadFileNamePath) {
  const std::string path = (folder_ / "bad.safetensors").string();
  {
    std::ofstream out(path, std::ios::binary);
    out << "short";
  }
  try {
    read_file(path);
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.origin(), path);
    EXPECT_EQ(std::string(e.what()).rfind(path + ": file is 5 bytes", 0), 0u) << e.what();
  }
}

// Found by model_fuzzer (issue 19; the input is fuzz/corpus/model/
// regression_number_overflow.safetensors): a header number beyond double's
// range threw the JSON library's out_of_range past parse(), which ended the
// program with std::terminate. It must be a FormatError like every other
// malformed header.
TEST(Safetensors, HeaderNumberBeyondDoubleIsAFormatError) {
  expect_rejected(file_bytes(R"({"__metadata__":{"a":"b"},"x":{"dtype":"F32","shape":[1e400],"data_offsets":[0,4]}})",
                             std::string(4, '\0')),
                  {"header is not readable JSON: a number beyond the range of a double"});
}

}  // namespace
}  // namespace hadynet::trainer::safetensors
