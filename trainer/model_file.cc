#include "trainer/model_file.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "trainer/model_limits.h"

namespace hadynet::trainer {

namespace st = safetensors;
using nlohmann::json;

namespace {

constexpr const char* kHeldOutLogsTensor = "held_out_logs.text";

std::vector<std::int64_t> shape_of(const NamedTensor<const float>& t) {
  if (t.rank == 1) return {t.rows};
  return {t.rows, t.cols};
}

st::Tensor f64_vector(const Eigen::VectorXd& v) {
  return st::make_f64({v.size()}, std::span<const double>(v.data(), static_cast<std::size_t>(v.size())));
}

// Row-major bytes of a (symmetric or not) matrix.
st::Tensor f64_matrix(const Eigen::MatrixXd& m) {
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> r = m;
  return st::make_f64({r.rows(), r.cols()},
                      std::span<const double>(r.data(), static_cast<std::size_t>(r.size())));
}

[[noreturn]] void fail(const std::string& origin, const std::string& message) {
  throw ModelFileError(origin + ": " + message);
}

json parse_metadata_json(const st::File& file, const std::string& key, const std::string& origin) {
  const auto it = file.metadata.find(key);
  if (it == file.metadata.end()) fail(origin, "metadata has no '" + key + "'");
  try {
    return json::parse(it->second);
  } catch (const json::exception& e) {
    fail(origin, "metadata '" + key + "' is not valid JSON: " + e.what());
  }
}

template <class T>
T json_get(const json& j, const std::string& key, const std::string& where,
           const std::string& origin) {
  if (!j.is_object() || !j.contains(key)) fail(origin, where + " has no '" + key + "'");
  try {
    return j.at(key).get<T>();
  } catch (const json::exception&) {
    fail(origin, where + " '" + key + "' has the wrong type");
  }
}

// A whole number in [lo, hi] (never a float, never wrapped): the reader's
// guard on every size it allocates from.
std::int64_t json_int(const json& j, const std::string& key, const std::string& where,
                      const std::string& origin, std::int64_t lo, std::int64_t hi) {
  if (!j.is_object() || !j.contains(key)) fail(origin, where + " has no '" + key + "'");
  const json& v = j.at(key);
  const bool in_range = v.is_number_unsigned() ? v.get<std::uint64_t>() <= static_cast<std::uint64_t>(hi)
                                               : v.is_number_integer() && v.get<std::int64_t>() <= hi;
  if (!v.is_number_integer() || !in_range || v.get<std::int64_t>() < lo) {
    fail(origin, where + " '" + key + "' must be a whole number in " + std::to_string(lo) + " .. " +
                     std::to_string(hi) + ", got " + v.dump());
  }
  return v.get<std::int64_t>();
}

// A finite number with |v| <= ModelLimits::kMaxMagnitude (and in [lo, hi]).
double json_number(const json& j, const std::string& key, const std::string& where, const std::string& origin,
                   double lo = -ModelLimits::kMaxMagnitude, double hi = ModelLimits::kMaxMagnitude) {
  const double v = json_get<double>(j, key, where, origin);
  if (!(v >= lo && v <= hi)) {
    char range[96];
    std::snprintf(range, sizeof range, "%g .. %g", lo, hi);
    fail(origin, where + " '" + key + "' must be a number in " + range + ", got " + j.at(key).dump());
  }
  return v;
}

// The stored held-out logs: metadata `logs` ([{"name", "bytes"}], in order)
// cutting the U8 tensor kHeldOutLogsTensor into texts. The texts are parsed
// where they are used (the residual loop), not here: loading stays cheap.
std::vector<StoredLog> held_out_logs_from(const st::File& file, const json& logs, const std::string& origin) {
  const auto tensor = file.tensors.find(kHeldOutLogsTensor);
  if (tensor == file.tensors.end()) fail(origin, std::string("metadata 'held_out_logs' without tensor '") +
                                                     kHeldOutLogsTensor + "'");
  const st::Tensor& t = tensor->second;
  if (t.dtype != st::DType::kU8 || t.shape.size() != 1)
    fail(origin, std::string("tensor '") + kHeldOutLogsTensor + "' must be U8 of rank 1");
  if (!logs.is_array() || logs.empty()) fail(origin, "metadata 'held_out_logs' must be a non-empty array");
  std::vector<StoredLog> out;
  std::size_t offset = 0;
  for (const json& entry : logs) {
    StoredLog log;
    log.name = json_get<std::string>(entry, "name", "held_out_logs entry", origin);
    const auto bytes = static_cast<std::size_t>(
        json_int(entry, "bytes", "held_out_logs entry", origin, 1, static_cast<std::int64_t>(t.bytes.size())));
    if (bytes > t.bytes.size() - offset)
      fail(origin, "metadata 'held_out_logs' counts more bytes than tensor '" + std::string(kHeldOutLogsTensor) +
                       "' holds (" + std::to_string(t.bytes.size()) + ")");
    log.text.assign(t.bytes.begin() + static_cast<std::ptrdiff_t>(offset),
                    t.bytes.begin() + static_cast<std::ptrdiff_t>(offset + bytes));
    offset += bytes;
    out.push_back(std::move(log));
  }
  if (offset != t.bytes.size())
    fail(origin, "tensor '" + std::string(kHeldOutLogsTensor) + "' holds " + std::to_string(t.bytes.size()) +
                     " bytes, metadata 'held_out_logs' counts " + std::to_string(offset));
  return out;
}

// Throws unless every value of `v` lies within +-ModelLimits::kMaxMagnitude.
template <class Values>
void check_magnitude(const Values& v, const std::string& what, const std::string& origin) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!(std::abs(v.data()[i]) <= ModelLimits::kMaxMagnitude)) {
      fail(origin, what + " holds " + std::to_string(v.data()[i]) + " at flat index " + std::to_string(i) +
                       "; stored numbers must be finite and within +-1e30");
    }
  }
}

// Parameters of a model of dims `d` (HadynetParams' tensors, summed in 64
// bits), so that the reader can compare them with what the file holds before
// it allocates anything.
std::int64_t parameter_count(const HadynetDims& d) {
  const std::int64_t h = d.hidden;
  return h * (d.x + d.pb) + 5 * h + 4 * h * (d.u + d.pb) + 4 * h * h + 8 * h + d.y * h + d.y +
         std::int64_t{d.states} * d.pb;
}

Eigen::VectorXd read_vector(const st::File& file, const std::string& name, std::int64_t n) {
  const std::vector<double> v = st::as_f64(file, name, {n});
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

Eigen::MatrixXd read_matrix(const st::File& file, const std::string& name, std::int64_t n) {
  const std::vector<double> v = st::as_f64(file, name, {n, n});
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      v.data(), static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
}

// The robot profile as metadata "profile" (its delta groups are in
// "channels"):
//   {"force_groups": [..], "angle_groups": [..], "length_groups": [..],
//    "control_commands": [..], "board_group": "fc",
//    "contact_sums": [{"name": "tips", "channels": ["fc0", ..]}, ..]}
json profile_json(const datalog::RobotProfile& p) {
  json sums = json::array();
  for (const datalog::ContactSum& c : p.contact_sums) sums.push_back({{"name", c.name}, {"channels", c.channels}});
  return json{{"force_groups", p.force_groups},         {"angle_groups", p.angle_groups},
              {"length_groups", p.length_groups},       {"control_commands", p.control_commands},
              {"board_group", p.board_group},           {"contact_sums", sums}};
}

datalog::RobotProfile profile_from_json(const json& j, const std::vector<std::string>& delta_groups,
                                        const std::string& origin) {
  if (!j.is_object()) fail(origin, "metadata 'profile' must be an object");
  datalog::RobotProfile p;
  p.delta_groups = delta_groups;
  p.force_groups = json_get<std::vector<std::string>>(j, "force_groups", "profile", origin);
  p.angle_groups = json_get<std::vector<std::string>>(j, "angle_groups", "profile", origin);
  p.length_groups = json_get<std::vector<std::string>>(j, "length_groups", "profile", origin);
  p.control_commands = json_get<std::vector<std::string>>(j, "control_commands", "profile", origin);
  p.board_group = json_get<std::string>(j, "board_group", "profile", origin);
  const json sums = j.contains("contact_sums") ? j.at("contact_sums") : json();
  if (!sums.is_array()) fail(origin, "metadata 'profile': 'contact_sums' must be a list");
  for (const json& c : sums) {
    p.contact_sums.push_back({json_get<std::string>(c, "name", "profile contact sum", origin),
                              json_get<std::vector<std::string>>(c, "channels", "profile contact sum", origin)});
  }
  return p;
}

// The sensor model (sensor_model.h) as metadata "sensor":
//   {"delays": [{"channel", "steps"}], "crosstalk": [{"target", "source", "gain"}],
//    "drifts": [{"channel", "driver": "level"|"time", "rate"}], "period_s": s,
//    "curves": [{"channel", "level": [knots], "reading": [knots]}] (optional, none if absent),
//    "clips": [{"channel", "side", "rail"}]}
json sensor_json(const SensorModel& s) {
  json j = json::object();
  j["delays"] = json::array();
  for (const auto& d : s.delays) j["delays"].push_back({{"channel", d.channel}, {"steps", d.steps}});
  j["crosstalk"] = json::array();
  for (const auto& x : s.crosstalk) j["crosstalk"].push_back({{"target", x.target}, {"source", x.source}, {"gain", x.gain}});
  j["drifts"] = json::array();
  for (const auto& d : s.drifts)
    j["drifts"].push_back({{"channel", d.channel}, {"driver", d.load ? "level" : "time"}, {"rate", d.rate}});
  j["period_s"] = s.period_s;
  if (!s.curves.empty()) {
    j["curves"] = json::array();
    for (const auto& c : s.curves)
      j["curves"].push_back({{"channel", c.channel}, {"level", c.level}, {"reading", c.reading}});
  }
  j["clips"] = json::array();
  for (const auto& c : s.clips) j["clips"].push_back({{"channel", c.channel}, {"side", c.side}, {"rail", c.rail}});
  return j;
}

json json_array(const json& j, const std::string& key, const std::string& origin) {
  const json a = j.is_object() && j.contains(key) ? j.at(key) : json();
  if (!a.is_array()) fail(origin, "sensor '" + key + "' is not an array");
  return a;
}

SensorModel sensor_from_json(const json& j, const std::string& origin) {
  SensorModel s;
  for (const json& d : json_array(j, "delays", origin))
    s.delays.push_back({json_get<std::string>(d, "channel", "sensor delay", origin),
                        static_cast<int>(json_int(d, "steps", "sensor delay", origin, 1, ModelLimits::kMaxDelaySteps))});
  // A cross-talk gain is a fraction of the source leaking into the target.
  for (const json& x : json_array(j, "crosstalk", origin))
    s.crosstalk.push_back({json_get<std::string>(x, "target", "sensor crosstalk", origin),
                           json_get<std::string>(x, "source", "sensor crosstalk", origin),
                           json_number(x, "gain", "sensor crosstalk", origin, -1.0, 1.0)});
  for (const json& d : json_array(j, "drifts", origin)) {
    const std::string driver = json_get<std::string>(d, "driver", "sensor drift", origin);
    // "load" (builds before stop 54): a bias that grew with the reading, its
    // own bias included; read as "level" it would predict another bias.
    if (driver == "load")
      fail(origin, "sensor drift driver 'load' (a bias growing with the reading, written by a build before the "
                   "level driver): run its --fix again");
    if (driver != "level" && driver != "time") fail(origin, "sensor drift driver '" + driver + "' is not level or time");
    s.drifts.push_back({json_get<std::string>(d, "channel", "sensor drift", origin), driver == "level",
                        json_number(d, "rate", "sensor drift", origin)});
  }
  s.period_s = json_number(j, "period_s", "sensor", origin, 0.0);
  if (j.contains("curves"))
    for (const json& c : json_array(j, "curves", origin)) {
      SensorCurve curve{json_get<std::string>(c, "channel", "sensor curve", origin),
                        json_get<std::vector<double>>(c, "level", "sensor curve", origin),
                        json_get<std::vector<double>>(c, "reading", "sensor curve", origin)};
      if (curve.level.size() > static_cast<std::size_t>(ModelLimits::kMaxCurveKnots))
        fail(origin, "sensor curve of " + curve.channel + " has " + std::to_string(curve.level.size()) +
                         " knots; at most " + std::to_string(ModelLimits::kMaxCurveKnots));
      check_magnitude(Eigen::Map<const Eigen::VectorXd>(curve.level.data(), static_cast<Eigen::Index>(curve.level.size())),
                      "sensor curve level", origin);
      check_magnitude(Eigen::Map<const Eigen::VectorXd>(curve.reading.data(), static_cast<Eigen::Index>(curve.reading.size())),
                      "sensor curve reading", origin);
      s.curves.push_back(std::move(curve));
    }
  for (const json& c : json_array(j, "clips", origin))
    s.clips.push_back({json_get<std::string>(c, "channel", "sensor clip", origin),
                       static_cast<int>(json_int(c, "side", "sensor clip", origin, -1, 1)),
                       json_number(c, "rail", "sensor clip", origin)});
  // A part this build does not know would be ignored and the model predict
  // wrongly: refused (a new part comes with a new format version).
  for (const auto& [key, value] : j.items())
    if (key != "delays" && key != "crosstalk" && key != "drifts" && key != "period_s" && key != "curves" &&
        key != "clips")
      fail(origin, "sensor model has an unknown part '" + key + "'");
  return s;
}

const char* const kNormTensors[] = {"norm.x_mean", "norm.x_std", "norm.u_mean",
                                    "norm.u_std",  "norm.y_mean", "norm.y_std"};

}  // namespace

int HadynetModel::state_index(const std::string& name) const {
  for (std::size_t k = 0; k < states.size(); ++k)
    if (states[k].name == name) return static_cast<int>(k);
  return -1;
}

void HadynetModel::check_consistent() const {
  const HadynetDims& d = params.dims;
  params.check_shapes();
  const auto need = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("model: " + what);
  };
  need(static_cast<int>(layout.x_names.size()) == d.x, "x channels differ from dims.x");
  need(static_cast<int>(layout.u_names.size()) == d.u, "u channels differ from dims.u");
  need(static_cast<int>(layout.y_names.size()) == d.y, "y channels differ from dims.y");
  need(static_cast<int>(states.size()) == d.states, "PB states differ from the PB table rows");
  need(norm.x.mean.size() == d.x && norm.x.std.size() == d.x, "x normalisation size");
  need(norm.u.mean.size() == d.u && norm.u.std.size() == d.u, "u normalisation size");
  need(norm.y.mean.size() == d.y && norm.y.std.size() == d.y, "y normalisation size");
  need((norm.x.std.array() > 0).all() && (norm.u.std.array() > 0).all() &&
           (norm.y.std.array() > 0).all(),
       "a normalisation std is not positive");
  need(train_steps >= 1, "train_steps < 1");
  need(period_s >= 0 && std::isfinite(period_s), "period_s negative or not finite");
  if (detection) {
    const DetectionCalibration& c = *detection;
    need(c.steps >= 1, "detection steps < 1");
    need(c.pb.size() == d.pb, "detection PB size");
    need(c.mean.size() == d.y && c.covariance.rows() == d.y && c.covariance.cols() == d.y &&
             c.inverse.rows() == d.y && c.inverse.cols() == d.y,
         "detection statistics sizes");
    need(std::isfinite(c.threshold) && c.threshold > 0, "detection threshold not positive");
  }
  try {
    sensor.check(layout.y_names);
  } catch (const std::invalid_argument& e) {
    need(false, e.what());
  }
  if (ranges) {
    for (const ValueRangeField& f : kValueRangeFields) {
      const double v = (*ranges).*f.member;
      need(std::isfinite(v) && v >= 0,
           std::string("range '") + f.name + "' is negative or not finite");
    }
    need(ranges->windows >= 0, "ranges windows < 0");
  }
}

st::File model_to_safetensors(const HadynetModel& model) {
  model.check_consistent();
  st::File file;
  for (const NamedTensor<const float>& t : model.params.tensors()) {
    file.tensors[std::string(t.name)] = st::make_f32(
        shape_of(t), std::span<const float>(t.data, static_cast<std::size_t>(t.size())));
  }
  st::Tensor tracked;  // I64 scalar, as PyTorch stores it
  tracked.dtype = st::DType::kI64;
  tracked.bytes.resize(sizeof(std::int64_t));
  const std::int64_t batches = model.bn_batches_tracked;
  std::memcpy(tracked.bytes.data(), &batches, sizeof batches);
  file.tensors["enc_bn.num_batches_tracked"] = std::move(tracked);
  const Eigen::VectorXd* norm[] = {&model.norm.x.mean, &model.norm.x.std, &model.norm.u.mean,
                                   &model.norm.u.std,  &model.norm.y.mean, &model.norm.y.std};
  for (std::size_t i = 0; i < 6; ++i) file.tensors[kNormTensors[i]] = f64_vector(*norm[i]);

  const HadynetDims& d = model.params.dims;
  file.metadata["format"] = kModelFormat;
  file.metadata["format_version"] =
      std::to_string(model.sensor.curves.empty() ? kModelFormatVersion : kModelFormatVersionCurves);
  file.metadata["dims"] = json{{"x", d.x},         {"u", d.u},           {"y", d.y},
                               {"pb", d.pb},       {"hidden", d.hidden}, {"states", d.states},
                               {"train_steps", model.train_steps}}
                              .dump();
  file.metadata["channels"] = json{{"x", model.layout.x_names},
                                   {"u", model.layout.u_names},
                                   {"y", model.layout.y_names},
                                   {"delta_groups", model.layout.delta_groups}}
                                  .dump();
  json states = json::array();
  for (const PbState& s : model.states) states.push_back({{"name", s.name}, {"object", s.object}});
  file.metadata["states"] = states.dump();
  file.metadata["hyper_parameters"] = json(model.hyper_parameters).dump();
  file.metadata["provenance"] = json(model.provenance).dump();
  if (model.detection) {
    const DetectionCalibration& c = *model.detection;
    file.metadata["detection"] = json{{"steps", c.steps},
                                      {"threshold", c.threshold},
                                      {"samples", c.samples},
                                      {"source", c.source}}
                                     .dump();
    file.tensors["detect.pb"] = f64_vector(c.pb);
    file.tensors["detect.mean"] = f64_vector(c.mean);
    file.tensors["detect.covariance"] = f64_matrix(c.covariance);
    file.tensors["detect.inverse"] = f64_matrix(c.inverse);
  }
  if (model.ranges) {
    json r = json::object();
    for (const ValueRangeField& f : kValueRangeFields) r[f.name] = (*model.ranges).*f.member;
    r["windows"] = model.ranges->windows;
    r["source"] = model.ranges->source;
    file.metadata["ranges"] = r.dump();
  }
  if (!model.sensor.empty()) file.metadata["sensor"] = sensor_json(model.sensor).dump();
  if (!model.profile.empty()) file.metadata["profile"] = profile_json(model.profile).dump();
  if (model.period_s > 0) file.metadata["period_s"] = json(model.period_s).dump();
  if (!model.held_out_logs.empty()) {
    // The logs' texts back to back in one U8 tensor; their names and byte
    // counts, in order, in the metadata.
    json logs = json::array();
    st::Tensor text{st::DType::kU8, {0}, {}};
    for (const StoredLog& log : model.held_out_logs) {
      logs.push_back({{"name", log.name}, {"bytes", log.text.size()}});
      text.bytes.insert(text.bytes.end(), log.text.begin(), log.text.end());
    }
    text.shape = {static_cast<std::int64_t>(text.bytes.size())};
    file.metadata["held_out_logs"] = logs.dump();
    file.tensors[kHeldOutLogsTensor] = std::move(text);
  }
  return file;
}

HadynetModel model_from_safetensors(const st::File& file, const std::string& origin,
                                    bool allow_optimizer_state) {
  const auto format = file.metadata.find("format");
  if (format == file.metadata.end() || format->second != kModelFormat) {
    fail(origin, std::string("not a HADYNET model (metadata 'format' must be '") + kModelFormat +
                     "')");
  }
  const auto version_it = file.metadata.find("format_version");
  const std::string version = version_it == file.metadata.end() ? std::string() : version_it->second;
  const bool curves_allowed = version == std::to_string(kModelFormatVersionCurves);
  if (!curves_allowed && version != std::to_string(kModelFormatVersion)) {
    fail(origin, "unsupported model format_version '" + version + "'; this build reads versions " +
                     std::to_string(kModelFormatVersion) + " and " + std::to_string(kModelFormatVersionCurves));
  }
  HadynetModel model;
  try {
    const json dims = parse_metadata_json(file, "dims", origin);
    HadynetDims d;
    const auto dim = [&](const char* key, std::int64_t hi) {
      return static_cast<int>(json_int(dims, key, "metadata 'dims'", origin, 1, hi));
    };
    d.x = dim("x", ModelLimits::kMaxX);
    d.u = dim("u", ModelLimits::kMaxChannels);
    d.y = dim("y", ModelLimits::kMaxChannels);
    d.pb = dim("pb", ModelLimits::kMaxPb);
    d.hidden = dim("hidden", ModelLimits::kMaxHidden);
    d.states = dim("states", ModelLimits::kMaxStates);
    model.train_steps = dim("train_steps", ModelLimits::kMaxTrainSteps);
    // The file must hold the parameters its dims promise before anything of
    // that size is allocated.
    std::int64_t stored_bytes = 0;
    for (const auto& [name, tensor] : file.tensors) stored_bytes += static_cast<std::int64_t>(tensor.bytes.size());
    if (4 * parameter_count(d) > stored_bytes) {
      fail(origin, "metadata 'dims' promises " + std::to_string(parameter_count(d)) +
                       " float32 parameters; the file's tensors hold " + std::to_string(stored_bytes) + " bytes");
    }

    const json channels = parse_metadata_json(file, "channels", origin);
    model.layout = feature_layout_from_names(
        json_get<std::vector<std::string>>(channels, "y", "channels", origin),
        json_get<std::vector<std::string>>(channels, "u", "channels", origin),
        json_get<std::vector<std::string>>(channels, "delta_groups", "channels", origin));
    if (json_get<std::vector<std::string>>(channels, "x", "channels", origin) !=
        model.layout.x_names) {
      fail(origin, "metadata 'channels': x does not follow from y and delta_groups");
    }

    model.profile.delta_groups = model.layout.delta_groups;
    if (file.metadata.count("profile") != 0) {
      model.profile = profile_from_json(parse_metadata_json(file, "profile", origin), model.layout.delta_groups, origin);
    }

    if (file.metadata.count("period_s") != 0) {
      // One network step, s (the training logs' dt_s); a JSON number.
      const json period = json{{"period_s", parse_metadata_json(file, "period_s", origin)}};
      model.period_s = json_number(period, "period_s", "metadata", origin, 1e-9, 1e6);
    }

    const json states = parse_metadata_json(file, "states", origin);
    if (!states.is_array()) fail(origin, "metadata 'states' must be a list");
    for (const json& s : states) {
      model.states.push_back({json_get<std::string>(s, "name", "a state", origin),
                              json_get<std::string>(s, "object", "a state", origin)});
    }
    model.hyper_parameters = parse_metadata_json(file, "hyper_parameters", origin)
                                 .get<std::map<std::string, std::string>>();
    model.provenance =
        parse_metadata_json(file, "provenance", origin).get<std::map<std::string, std::string>>();

    // Tensors: exactly the expected set.
    std::set<std::string> expected;
    model.params = HadynetParams<float>::zeros(d);
    for (NamedTensor<float> t : model.params.tensors()) {
      const std::string name(t.name);
      expected.insert(name);
      std::vector<std::int64_t> shape{t.rows};
      if (t.rank == 2) shape.push_back(t.cols);
      const std::vector<float> v = st::as_f32(file, name, shape);
      for (std::size_t i = 0; i < v.size(); ++i) {
        if (!std::isfinite(v[i])) fail(origin, "tensor '" + name + "' holds a non-finite value");
        if (!(std::abs(v[i]) <= ModelLimits::kMaxMagnitude)) {
          fail(origin, "tensor '" + name + "' holds " + std::to_string(v[i]) + " at flat index " +
                           std::to_string(i) + "; stored numbers must be within +-1e30");
        }
        t.data[i] = v[i];
      }
    }
    expected.insert("enc_bn.num_batches_tracked");
    const auto tracked = file.tensors.find("enc_bn.num_batches_tracked");
    if (tracked == file.tensors.end() || tracked->second.dtype != st::DType::kI64 ||
        !tracked->second.shape.empty()) {
      fail(origin, "tensor 'enc_bn.num_batches_tracked' missing or not an I64 scalar");
    }
    std::int64_t batches = 0;
    std::memcpy(&batches, tracked->second.bytes.data(), sizeof batches);
    model.bn_batches_tracked = static_cast<long>(batches);

    const std::int64_t sizes[] = {d.x, d.x, d.u, d.u, d.y, d.y};
    Eigen::VectorXd* norm[] = {&model.norm.x.mean, &model.norm.x.std, &model.norm.u.mean,
                               &model.norm.u.std,  &model.norm.y.mean, &model.norm.y.std};
    for (std::size_t i = 0; i < 6; ++i) {
      expected.insert(kNormTensors[i]);
      *norm[i] = read_vector(file, kNormTensors[i], sizes[i]);
      check_magnitude(*norm[i], kNormTensors[i], origin);
      if (i % 2 == 1) {  // a std
        for (Eigen::Index k = 0; k < norm[i]->size(); ++k) {
          if (!((*norm[i])(k) >= ModelLimits::kMinStd)) {
            fail(origin, std::string(kNormTensors[i]) + " holds " + std::to_string((*norm[i])(k)) + " at index " +
                             std::to_string(k) + "; a standardisation std must be at least 1e-12");
          }
        }
      }
    }

    if (file.metadata.count("detection") != 0) {
      const json det = parse_metadata_json(file, "detection", origin);
      DetectionCalibration c;
      c.steps = static_cast<int>(json_int(det, "steps", "detection", origin, 1, model.train_steps));
      c.threshold = json_number(det, "threshold", "detection", origin, 0.0);
      c.samples = static_cast<long>(json_int(det, "samples", "detection", origin, 0,
                                             std::int64_t{1} << 53));
      c.source = json_get<std::string>(det, "source", "detection", origin);
      c.pb = read_vector(file, "detect.pb", d.pb);
      c.mean = read_vector(file, "detect.mean", d.y);
      c.covariance = read_matrix(file, "detect.covariance", d.y);
      c.inverse = read_matrix(file, "detect.inverse", d.y);
      check_magnitude(c.pb, "detect.pb", origin);
      check_magnitude(c.mean, "detect.mean", origin);
      check_magnitude(c.covariance, "detect.covariance", origin);
      check_magnitude(c.inverse, "detect.inverse", origin);
      for (const char* n : {"detect.pb", "detect.mean", "detect.covariance", "detect.inverse"})
        expected.insert(n);
      model.detection = std::move(c);
    }

    if (file.metadata.count("ranges") != 0) {
      const json r = parse_metadata_json(file, "ranges", origin);
      ValueRanges ranges;
      for (const ValueRangeField& f : kValueRangeFields)
        ranges.*f.member = json_number(r, f.name, "ranges", origin, 0.0);
      ranges.windows = static_cast<long>(json_int(r, "windows", "ranges", origin, 0,
                                                  std::int64_t{1} << 53));
      ranges.source = json_get<std::string>(r, "source", "ranges", origin);
      model.ranges = std::move(ranges);
    }

    if (file.metadata.count("sensor") != 0)
      model.sensor = sensor_from_json(parse_metadata_json(file, "sensor", origin), origin);
    if (!model.sensor.curves.empty() && !curves_allowed)
      fail(origin, "the sensor model has calibration curves, which need format_version " +
                       std::to_string(kModelFormatVersionCurves) + " (the file says " +
                       std::to_string(kModelFormatVersion) +
                       "; builds before the version existed wrote curves as 1: run its --fix again)");

    if (file.metadata.count("held_out_logs") != 0) {
      model.held_out_logs = held_out_logs_from(file, parse_metadata_json(file, "held_out_logs", origin), origin);
      expected.insert(kHeldOutLogsTensor);
    }

    for (const auto& [name, tensor] : file.tensors) {
      if (expected.count(name) != 0) continue;
      if (allow_optimizer_state && name.rfind("optim.", 0) == 0) continue;
      fail(origin, "unexpected tensor '" + name + "'");
    }
    model.check_consistent();
  } catch (const st::FormatError& e) {
    fail(origin, e.message());
  } catch (const std::invalid_argument& e) {
    fail(origin, e.what());
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const ModelFileError*>(&e) != nullptr) throw;
    fail(origin, e.what());
  } catch (const json::exception& e) {
    fail(origin, std::string("metadata: ") + e.what());
  }
  return model;
}

void save_model(const std::string& path, const HadynetModel& model) {
  st::write_file(path, model_to_safetensors(model));
}

HadynetModel load_model(const std::string& path) {
  st::File file;
  try {
    file = st::read_file(path);
  } catch (const st::FormatError& e) {
    throw ModelFileError(e.what());
  }
  return model_from_safetensors(file, path);
}

}  // namespace hadynet::trainer
