// hadynet recognize: object recognition by PB (seed paper III-C): adapt one PB
// per dynamics state of the logs, take the nearest trained PB, report its
// object with its margin (clear / ambiguous; trainer::recognize_object), and
// draw the PB map (PCA of the trained PBs, coloured by object, the adapted
// PBs marked, ambiguous ones with "?").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/options.h"
#include "cli/pb_adapt_common.h"
#include "cli/pb_map_plot.h"
#include "cli/trainer_inputs.h"
#include "datalog/log_rules.h"
#include "trainer/model_file.h"
#include "trainer/recognition.h"

namespace hadynet::cli {


int run_recognize(int argc, char** argv) {
  Options opt("recognize",
              "Recognises the grasped object: adapts one PB per dynamics state of the logs (as `adapt`), finds\n"
              "the nearest trained PB (Euclidean) and reports that state's object, with its margin (distance\n"
              "to the nearest other object over distance to the recognised one) and a confidence word: clear\n"
              "from --clear-margin on, else ambiguous. When the logs name their object (metadata 'object')\n"
              "the accuracy is printed; objects the model never saw are listed with the two nearest known\n"
              "objects. --plot draws the PB map (ambiguous points marked '?').",
              "MODEL LOG|DIR... [options]");
  add_adapt_options(opt);
  opt.value("plot", "PNG", "draw the PB map (PCA of the trained PBs) with the adapted PBs marked");
  opt.value("json", "FILE", "write the results as JSON");
  opt.value("clear-margin", "M",
            "margin (distance to the nearest other object / to the recognised one) from which a\n"
            "recognition is called clear, below it ambiguous (chosen on validation zeroings; docs/trainer.md)",
            datalog::rules::format_number(trainer::kClearRecognitionMargin));
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (opt.positional().size() < 2) {
    std::fprintf(stderr, "hadynet recognize: give MODEL and logs (see --help)\n");
    return 2;
  }
  const auto adapt = adapt_options(opt);
  const auto clear_margin = opt.get_double("clear-margin", 1.0, 1e6);
  if (!clear_margin) return 2;
  if (!adapt) return 2;
  try {
    const trainer::HadynetModel model = trainer::load_model(opt.positional().front());
    const std::vector<std::string> log_args(opt.positional().begin() + 1, opt.positional().end());
    const std::vector<AdaptedState> adapted =
        adapt_each_state(model, group_by_state(read_sequences(log_args, model)),
                         parse_start_pbs(model, opt.get("start")), *adapt);

    std::printf("%-22s %-11s %-11s %-22s %8s %6s %-9s  %s\n", "state", "true", "recognised", "nearest state",
                "distance", "margin", "", "next objects (distance)");
    int known = 0, correct = 0;
    std::vector<MarkedPb> marked;
    nlohmann::json results = nlohmann::json::array();
    for (const AdaptedState& a : adapted) {
      const trainer::Recognition rec = trainer::recognize_object(model, a.result.pb, *clear_margin);
      const trainer::NearestPb& nn = rec.nearest;
      const trainer::PbState& hit = model.states[static_cast<std::size_t>(nn.state)];
      const auto& objects = rec.objects_by_distance;
      const char* confidence = rec.clear ? "clear" : "ambiguous";
      std::string next;
      for (std::size_t i = 1; i < std::min<std::size_t>(3, objects.size()); ++i) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%s%s (%.3f)", i > 1 ? ", " : "", objects[i].first.c_str(),
                      objects[i].second);
        next += buf;
      }
      const bool object_known =
          std::any_of(model.states.begin(), model.states.end(),
                      [&](const trainer::PbState& s) { return s.object == a.object; });
      const char* verdict = "";
      if (object_known && !a.object.empty()) {
        ++known;
        if (hit.object == a.object) ++correct;
        verdict = hit.object == a.object ? "" : "  WRONG";
      } else {
        verdict = "  (object not in the model)";
      }
      std::printf("%-22s %-11s %-11s %-22s %8.3f %6.2f %-9s  %s%s\n", a.state.c_str(), a.object.c_str(),
                  hit.object.c_str(), hit.name.c_str(), nn.distance, rec.margin, confidence, next.c_str(), verdict);
      marked.push_back({(a.object.empty() ? a.state : a.object + " (" + a.state + ")") + (rec.clear ? "" : " ?"),
                        a.result.pb});
      nlohmann::json nearest = nlohmann::json::array();
      for (const auto& [object, dist] : objects) nearest.push_back({{"object", object}, {"distance", dist}});
      results.push_back({{"state", a.state},
                         {"object", a.object},
                         {"recognised", hit.object},
                         {"nearest_state", hit.name},
                         {"distance", nn.distance},
                         {"margin", std::isfinite(rec.margin) ? nlohmann::json(rec.margin) : nlohmann::json(nullptr)},
                         {"confidence", confidence},
                         {"objects_by_distance", nearest},
                         {"adapt_loss_before", a.result.loss.front()},
                         {"adapt_loss_after", a.result.loss.back()},
                         {"pb", std::vector<float>(a.result.pb.data(), a.result.pb.data() + a.result.pb.size())}});
    }
    if (known > 0) std::printf("accuracy: %d of %d states recognised correctly\n", correct, known);
    if (opt.has("json")) {
      std::ofstream out(opt.get("json"));
      if (!out) throw std::runtime_error(opt.get("json") + ": cannot write");
      out << nlohmann::json{{"results", results}, {"correct", correct}, {"known", known}}.dump(2)
          << '\n';
      std::fprintf(stderr, "wrote %s\n", opt.get("json").c_str());
    }
    if (opt.has("plot")) {
      const std::string err =
          plot_pb_map(model, marked, {}, "PB map: trained PBs by object, adapted PBs marked", opt.get("plot"));
      if (!err.empty()) throw std::runtime_error(err);
      std::fprintf(stderr, "wrote %s\n", opt.get("plot").c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet recognize: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
