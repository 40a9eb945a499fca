#include "trainer/checkpoint.h"

#include <cmath>
#include <limits>
#include <utility>
#include <nlohmann/json.hpp>

#include "trainer/model_file.h"

namespace hadynet::trainer {

namespace st = safetensors;
using nlohmann::json;

void save_checkpoint(const std::string& path, const Checkpoint& checkpoint) {
  st::File file = model_to_safetensors(checkpoint.model);
  const std::vector<NamedTensor<const float>> tensors = checkpoint.model.params.tensors();
  const Adam<float>::State& adam = checkpoint.state.adam;
  json steps = json::object();
  for (std::size_t i = 0; i < adam.m.size() && i < tensors.size(); ++i) {
    if (adam.m[i].size() == 0) continue;
    const std::string name(tensors[i].name);
    const auto n = static_cast<std::size_t>(adam.m[i].size());
    file.tensors["optim.adam.m." + name] =
        st::make_f32({adam.m[i].size()}, std::span<const float>(adam.m[i].data(), n));
    file.tensors["optim.adam.v." + name] =
        st::make_f32({adam.v[i].size()}, std::span<const float>(adam.v[i].data(), n));
    steps[name] = adam.t[i];
  }
  json history = json::array();
  for (const EpochStats& e : checkpoint.state.history) {
    history.push_back({e.epoch, e.train_loss,
                       std::isfinite(e.held_out_loss) ? json(e.held_out_loss) : json(nullptr),
                       e.seconds});
  }
  const TrainOptions& o = checkpoint.options;
  file.metadata["checkpoint"] = json{{"epochs_done", checkpoint.state.epochs_done},
                                     {"adam_steps", steps},
                                     {"history", history},
                                     {"epochs", o.epochs},
                                     {"batch", o.batch},
                                     {"lr", o.lr},
                                     {"seed", std::to_string(o.seed)},
                                     {"variable_pb", o.variable_pb}}
                                    .dump();
  st::write_file(path, file);
}

Checkpoint load_checkpoint(const std::string& path) {
  st::File file;
  try {
    file = st::read_file(path);
  } catch (const st::FormatError& e) {
    throw ModelFileError(e.what());
  }
  Checkpoint c;
  c.model = model_from_safetensors(file, path, /*allow_optimizer_state=*/true);
  const auto it = file.metadata.find("checkpoint");
  if (it == file.metadata.end()) {
    throw ModelFileError(path + ": a model file, not a checkpoint (no 'checkpoint' metadata)");
  }
  try {
    const json j = json::parse(it->second);
    c.state.epochs_done = j.at("epochs_done").get<int>();
    c.options.epochs = j.at("epochs").get<int>();
    c.options.batch = j.at("batch").get<int>();
    c.options.lr = j.at("lr").get<double>();
    c.options.seed = std::stoull(j.at("seed").get<std::string>());
    c.options.variable_pb = j.at("variable_pb").get<bool>();
    for (const json& e : j.at("history")) {
      EpochStats s;
      s.epoch = e.at(0).get<int>();
      s.train_loss = e.at(1).get<double>();
      s.held_out_loss =
          e.at(2).is_null() ? std::numeric_limits<double>::quiet_NaN() : e.at(2).get<double>();
      s.seconds = e.at(3).get<double>();
      c.state.history.push_back(s);
    }
    const json& steps = j.at("adam_steps");
    const std::vector<NamedTensor<const float>> tensors =
        std::as_const(c.model.params).tensors();
    Adam<float>::State& adam = c.state.adam;
    adam.m.resize(tensors.size());
    adam.v.resize(tensors.size());
    adam.t.assign(tensors.size(), 0);
    for (std::size_t i = 0; i < tensors.size(); ++i) {
      const std::string name(tensors[i].name);
      if (!steps.contains(name)) continue;
      const std::int64_t n = tensors[i].size();
      const std::vector<float> m = st::as_f32(file, "optim.adam.m." + name, {n});
      const std::vector<float> v = st::as_f32(file, "optim.adam.v." + name, {n});
      adam.m[i] = Eigen::Map<const Vector<float>>(m.data(), n);
      adam.v[i] = Eigen::Map<const Vector<float>>(v.data(), n);
      adam.t[i] = steps.at(name).get<long>();
    }
  } catch (const json::exception& e) {
    throw ModelFileError(path + ": checkpoint metadata: " + e.what());
  } catch (const st::FormatError& e) {
    throw ModelFileError(path + ": " + e.message());  // what() already starts with the path
  } catch (const std::logic_error& e) {
    throw ModelFileError(path + ": checkpoint metadata: " + e.what());
  }
  return c;
}

}  // namespace hadynet::trainer
