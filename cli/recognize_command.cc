// hadynet recognize: object recognition by PB (seed paper III-C): adapt one PB
// per dynamics state of the logs, take the nearest trained PB, report its
// object with its margin (clear / ambiguous; trainer::recognize_object), and
// draw the PB map (PCA of the trained PBs, coloured by object, the adapted
// PBs marked, ambiguous ones with "?").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/options.h"
#include "cli/pb_adapt_common.h"
#include "cli/pb_map_plot.h"
#include "cli/threads_option.h"
#include "cli/trainer_inputs.h"
#include "datalog/log_rules.h"
#include "trainer/model_file.h"
#include "trainer/recognition.h"

namespace hadynet::cli {


int run_recognize(int argc, char** argv) {
  Options opt("recognize",
              "Recognises the grasped object: adapts one PB per dynamics state of the logs (as `adapt`) and\n"
              "names the nearest object in the --metric: within-object (default; the distance to each\n"
              "object's mean trained PB measured against how the object's trained PBs spread over zeroings)\n"
              "or nearest-state (Euclidean distance to the nearest trained PB, the paper's rule). It reports\n"
              "the nearest trained state too, the margin (distance to the nearest other object over distance\n"
              "to the recognised one) and a confidence word: clear from --clear-margin on, else ambiguous.\n"
              "When the logs name their object (metadata 'object') the accuracy is printed; objects the\n"
              "model never saw are listed with the two nearest known objects. --plot draws the PB map\n"
              "(ambiguous points marked '?').",
              "MODEL LOG|DIR... [options]");
  add_adapt_options(opt);
  add_threads_option(opt, "1");
  opt.value("plot", "PNG", "draw the PB map (PCA of the trained PBs) with the adapted PBs marked");
  opt.value("json", "FILE", "write the results as JSON");
  opt.value("metric", "M",
            "within-object or nearest-state (docs/trainer.md, \"Recognition over many zeroings\")",
            trainer::metric_name(trainer::kDefaultRecognitionMetric));
  opt.value("clear-margin", "M",
            "margin (distance to the nearest other object / to the recognised one) from which a\n"
            "recognition is called clear, below it ambiguous (chosen on validation zeroings; docs/trainer.md;\n"
            "default " +
                datalog::rules::format_number(trainer::kClearWithinObjectMargin) + " within-object, " +
                datalog::rules::format_number(trainer::kClearRecognitionMargin) + " nearest-state)");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (!apply_threads_option(opt, "recognize")) return 2;
  if (opt.positional().size() < 2) {
    std::fprintf(stderr, "hadynet recognize: give MODEL and logs (see --help)\n");
    return 2;
  }
  const auto adapt = adapt_options(opt);
  trainer::RecognitionMetric metric{};
  if (!trainer::parse_recognition_metric(opt.get("metric"), metric)) {
    std::fprintf(stderr, "hadynet recognize: --metric: '%s' is not within-object or nearest-state\n",
                 opt.get("metric").c_str());
    return 2;
  }
  std::optional<double> clear_margin = trainer::default_clear_margin(metric);
  if (opt.has("clear-margin")) clear_margin = opt.get_double("clear-margin", 1.0, 1e6);
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
    bool said_fallback = false;
    std::vector<MarkedPb> marked;
    nlohmann::json results = nlohmann::json::array();
    for (const AdaptedState& a : adapted) {
      const trainer::Recognition rec = trainer::recognize_object(model, a.result.pb, *clear_margin, metric);
      if (rec.metric != metric && !said_fallback) {
        std::printf("(no object has two trained PBs, so no within-object spread: nearest-state distances)\n");
        said_fallback = true;
      }
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
        if (rec.object == a.object) ++correct;
        verdict = rec.object == a.object ? "" : "  WRONG";
      } else {
        verdict = "  (object not in the model)";
      }
      std::printf("%-22s %-11s %-11s %-22s %8.3f %6.2f %-9s  %s%s\n", a.state.c_str(), a.object.c_str(),
                  rec.object.c_str(), hit.name.c_str(), nn.distance, rec.margin, confidence, next.c_str(), verdict);
      marked.push_back({(a.object.empty() ? a.state : a.object + " (" + a.state + ")") + (rec.clear ? "" : " ?"),
                        a.result.pb});
      nlohmann::json nearest = nlohmann::json::array();
      for (const auto& [object, dist] : objects) nearest.push_back({{"object", object}, {"distance", dist}});
      results.push_back({{"state", a.state},
                         {"object", a.object},
                         {"recognised", rec.object},
                         {"metric", trainer::metric_name(rec.metric)},
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
