#include "trainer/data_hash.h"
#include "trainer/training_record.h"

#include <ctime>
#include <stdexcept>

namespace hadynet::trainer {

PbStateTable pb_state_table(const std::vector<LogSequence>& sequences) {
  std::map<std::string, std::string> object_of_state;  // sorted by state name
  for (const auto& seq : sequences) {
    const auto [it, inserted] = object_of_state.emplace(seq.state, seq.object);
    if (!inserted && it->second != seq.object) {
      throw std::runtime_error(seq.file + ": state '" + seq.state + "' has object '" + seq.object + "' here but '" +
                               it->second + "' in another log");
    }
  }
  PbStateTable table;
  std::map<std::string, int> row_of_state;
  for (const auto& [state, object] : object_of_state) {
    row_of_state[state] = static_cast<int>(table.states.size());
    table.states.push_back({state, object});
  }
  for (const auto& seq : sequences) table.state_of_sequence.push_back(row_of_state.at(seq.state));
  return table;
}

std::map<std::string, std::string> training_provenance(const std::vector<std::string>& log_paths,
                                                       const std::string& git_commit, const std::string& version) {
  return {{"data_hash", data_hash(log_paths)},
          {"git_commit", git_commit},
          {"hadynet_version", version},
          {"logs", std::to_string(log_paths.size())},
          {"created_utc", utc_now()}};
}

std::map<std::string, std::string> training_hyper_parameters(const TrainOptions& options, const TrainingShape& shape) {
  return {{"epochs", std::to_string(options.epochs)},
          {"batch", std::to_string(options.batch)},
          {"steps", std::to_string(shape.steps)},
          {"lr", shape.lr_text},
          {"optimizer", "Adam(beta1=0.9, beta2=0.999, eps=1e-8)"},
          {"seed", std::to_string(options.seed)},
          {"variable_pb", options.variable_pb ? "true" : "false"},
          {"held_out_fraction", shape.held_out_text},
          {"train_windows", std::to_string(shape.train_windows)},
          {"held_out_windows", std::to_string(shape.held_out_windows)},
          {"loss", "MSE, standardised units"}};
}

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace hadynet::trainer
