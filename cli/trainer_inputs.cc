#include "cli/trainer_inputs.h"

#include "datalog/log_reader.h"
#include "trainer/recognition.h"

#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace hadynet::cli {

std::vector<trainer::LogSequence> read_sequences(const std::vector<std::string>& args,
                                                 const trainer::FeatureLayout& layout) {
  std::vector<trainer::LogSequence> out;
  for (const std::string& path : trainer::expand_log_paths(args))
    out.push_back(trainer::read_sequence(path, layout));
  return out;
}

std::vector<trainer::LogSequence> read_sequences(const std::vector<std::string>& args,
                                                 const trainer::HadynetModel& model) {
  std::vector<trainer::LogSequence> out;
  for (const std::string& path : trainer::expand_log_paths(args)) {
    const datalog::LogTable table = datalog::read_log(path);
    datalog::channel_layout(table, path);  // header rules
    out.push_back(trainer::in_model_frame(model.sensor, model.layout, table, path).sequence);
  }
  return out;
}

std::vector<StateGroup> group_by_state(std::vector<trainer::LogSequence> sequences) {
  std::vector<StateGroup> groups;
  for (trainer::LogSequence& seq : sequences) {
    StateGroup* group = nullptr;
    for (StateGroup& g : groups)
      if (g.state == seq.state) group = &g;
    if (group == nullptr) {
      groups.push_back({seq.state, seq.object, {}});
      group = &groups.back();
    }
    group->sequences.push_back(std::move(seq));
  }
  return groups;
}

Eigen::VectorXf parse_pb(const trainer::HadynetModel& model, const std::string& text) {
  const int dim = model.params.dims.pb;
  if (text == "zero") return Eigen::VectorXf::Zero(dim);
  if (const int k = model.state_index(text); k >= 0) return model.params.pb.row(k).transpose();
  std::vector<float> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stof(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw std::runtime_error("PB '" + text +
                               "' is neither 'zero', a state of the model, nor numbers");
    }
  }
  if (static_cast<int>(values.size()) != dim) {
    throw std::runtime_error("PB '" + text + "' has " + std::to_string(values.size()) +
                             " values, the model's PB has " + std::to_string(dim));
  }
  return Eigen::Map<const Eigen::VectorXf>(values.data(), dim);
}

std::vector<Eigen::VectorXf> parse_start_pbs(const trainer::HadynetModel& model, const std::string& text) {
  if (text != "objects") return {parse_pb(model, text)};
  std::vector<Eigen::VectorXf> starts = {Eigen::VectorXf::Zero(model.params.dims.pb)};
  for (Eigen::VectorXf& pb : trainer::object_mean_pbs(model)) starts.push_back(std::move(pb));
  return starts;
}

std::string format_pb(const Eigen::VectorXf& pb) {
  std::string s;
  char buf[32];
  for (Eigen::Index i = 0; i < pb.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%s%.4f", i ? "," : "", static_cast<double>(pb(i)));
    s += buf;
  }
  return s;
}

}  // namespace hadynet::cli
