#include "cli/pb_adapt_common.h"

#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <stdexcept>

#include "trainer/window_dataset.h"

namespace hadynet::cli {

void add_adapt_options(Options& opt) {
  const trainer::AdaptOptions d;
  opt.value("start", "PB", "initial PB: zero, a state of the model, comma-separated values, or objects\n"
            "(zero and each object's mean trained PB, keeping the best fit)", "zero");
  opt.value("epochs", "N", "full-batch epochs (paper: 20)", std::to_string(d.epochs));
  opt.value("lr", "X", "MomentumSGD learning rate", "1.0");
  opt.value("momentum", "X", "MomentumSGD momentum", "0.9");
}

std::optional<trainer::AdaptOptions> adapt_options(const Options& opt) {
  const auto epochs = opt.get_int("epochs", 1, 1000000);
  const auto lr = opt.get_double("lr", 1e-12, 1e6);
  const auto momentum = opt.get_double("momentum", 0.0, 0.999999);
  if (!epochs || !lr || !momentum) return std::nullopt;
  return trainer::AdaptOptions{static_cast<int>(*epochs), *lr, *momentum};
}

std::vector<AdaptedState> adapt_each_state(const trainer::HadynetModel& model,
                                           const std::vector<StateGroup>& groups,
                                           const std::vector<Eigen::VectorXf>& starts,
                                           const trainer::AdaptOptions& options) {
  std::vector<AdaptedState> out;
  for (const StateGroup& g : groups) {
    const trainer::WindowDataset data(g.sequences, std::vector<int>(g.sequences.size(), 0),
                                      model.layout, model.norm, model.train_steps);
    if (data.size() == 0) {
      throw std::runtime_error("state '" + g.state + "': logs too short for one window of " +
                               std::to_string(model.train_steps) + " steps");
    }
    std::vector<int> ids(static_cast<std::size_t>(data.size()));
    std::iota(ids.begin(), ids.end(), 0);
    out.push_back({g.state, g.object, data.size(),
                   trainer::adapt_pb_best_of(model, data, ids, starts, options)});
    if (!out.back().result.pb.allFinite()) {
      // Never print or store a NaN PB as a result.
      throw std::runtime_error("state '" + g.state + "': PB adaptation diverged (the PB is not finite); try a "
                               "smaller --lr");
    }
  }
  return out;
}

void write_adapt_json(const std::string& path, const std::vector<AdaptedState>& results) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& r : results) {
    j.push_back({{"state", r.state},
                 {"object", r.object},
                 {"windows", r.windows},
                 {"loss", r.result.loss},
                 {"drop_percent", r.drop_percent()},
                 {"lr_halvings", r.result.halvings},
                 {"pb", std::vector<float>(r.result.pb.data(), r.result.pb.data() + r.result.pb.size())}});
  }
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << j.dump(2) << '\n';
}

}  // namespace hadynet::cli
