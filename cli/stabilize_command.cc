// hadynet stabilize: host-sim — the seed paper's grasp-stabiliser experiment
// (section IV-E). The firmware core (the build's generated model) runs in
// closed loop with the MuJoCo hand (hostsim::run_closed_loop) on one grasp
// under a scripted disturbance, once holding the command (u = 0) and once
// with the grasp stabiliser; prints the mean evaluation value
// E = h_loss,1 (N^2) of both runs, --csv writes them per step, --plot draws
// E and the stabiliser's commands.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "cli/commands.h"
#include "cli/error_text.h"
#include "cli/gnuplot.h"
#include "cli/options.h"
#include "host-sim/closed_loop/closed_loop.h"
#include "host-sim/plant/disturbance.h"
#include "host-sim/plant/experiment.h"
#include "host-sim/plant/hand_spec.h"

namespace hadynet::cli {

namespace {

// Rows [begin, end) for one of the summary's means (row = steps since the grasp).
struct Window {
  std::size_t begin = 0, end = 0;
  std::string label() const { return "steps " + std::to_string(begin) + ".." + std::to_string(end - 1); }
};

// A number for gnuplot's log-scale E axis: E <= 0 (row 0, y = y_ref) is left
// out ("NaN" is an undefined point to gnuplot).
std::string log_axis_value(double v) {
  if (!(v > 0.0) || !std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// `without` may be null (--only-control).
std::string stabilize_plot(const hostsim::ClosedLoopRun* without, const hostsim::ClosedLoopRun& with,
                           const std::string& title, const std::string& png) {
  std::string s = "$e << EOD\n";
  char buf[64];
  for (std::size_t t = 0; t < with.steps.size(); ++t) {
    const auto& w = with.steps[t];
    s += std::to_string(w.step) + " " + (without ? log_axis_value(without->steps[t].grasp_error) : "NaN") + " " +
         log_axis_value(w.grasp_error);
    std::snprintf(buf, sizeof buf, " %.6g\n", w.force_N);
    s += buf;
  }
  s += "EOD\n$u << EOD\n";
  for (const auto& w : with.steps) {
    s += std::to_string(w.step);
    for (double v : w.command) {
      std::snprintf(buf, sizeof buf, " %.6g", v);
      s += buf;
    }
    s += "\n";
  }
  s += "EOD\n";
  s += "set terminal pngcairo size 1200,800 font 'sans,9' noenhanced\n";
  s += "set output " + gnuplot_quote(png) + "\n";
  s += "set multiplot layout 2,1 title " + gnuplot_quote(title) + "\n";
  s += "set grid\nset key outside right top\nset lmargin 10\nset rmargin 28\nset xlabel 'step (0.2 s)'\n";
  s += "set xrange [0:" + std::to_string(with.steps.empty() ? 1 : with.steps.back().step) + "]\n";
  s += "set ylabel 'E = h_loss,1 [N^2]'\nset logscale y\n";
  s += "set y2label 'strike force |F| [N]'\nset y2tics\nset y2range [0:*]\n";
  s += "plot $e using 1:4 axes x1y2 with impulses lw 3 lc rgb 'gray70' title 'strike force [N]'";
  if (without) s += ", $e using 1:2 with lines lw 2 lc rgb 'red' title 'E without control'";
  s += ", $e using 1:3 with lines lw 2 lc rgb 'blue' title 'E with stabiliser'\n";
  s += "unset logscale y\nunset y2label\nunset y2tics\n";
  s += "set ylabel 'stabiliser command u [mm]'\n";
  s += "plot ";
  for (std::size_t i = 0; i < with.u_names.size(); ++i) {
    if (i) s += ", ";
    s += "$u using 1:" + std::to_string(i + 2) + " with lines title " + gnuplot_quote(with.u_names[i]);
  }
  s += "\nunset multiplot\n";
  return run_gnuplot(s, png);
}

// Per step: the disturbance, E of both runs, the firmware's contact flag and
// d in both runs, and the controlled run's commands. Columns of the
// uncontrolled run are left out when it was not run.
void write_csv(std::FILE* f, const hostsim::ClosedLoopRun* without, const hostsim::ClosedLoopRun& with) {
  std::fprintf(f, "step,force_N");
  if (without) std::fprintf(f, ",E_without_N2");
  std::fprintf(f, ",E_with_N2");
  if (without) std::fprintf(f, ",contact_without");
  std::fprintf(f, ",contact_with");
  if (without) std::fprintf(f, ",d_without");
  std::fprintf(f, ",d_with");
  for (const auto& name : with.u_names) std::fprintf(f, ",cmd_%s", name.c_str());
  std::fprintf(f, "\n");
  for (std::size_t t = 0; t < with.steps.size(); ++t) {
    const auto& w = with.steps[t];
    const hostsim::ClosedLoopStep* o = without ? &without->steps[t] : nullptr;
    std::fprintf(f, "%d,%.9g", w.step, w.force_N);
    if (o) std::fprintf(f, ",%.9g", o->grasp_error);
    std::fprintf(f, ",%.9g", w.grasp_error);
    if (o) std::fprintf(f, ",%d", o->contact ? 1 : 0);
    std::fprintf(f, ",%d", w.contact ? 1 : 0);
    if (o) std::fprintf(f, ",%.9g", static_cast<double>(o->d));
    std::fprintf(f, ",%.9g", static_cast<double>(w.d));
    for (double v : w.command) std::fprintf(f, ",%.9g", v);
    std::fprintf(f, "\n");
  }
}

}  // namespace

int run_stabilize(int argc, char** argv) {
  const hostsim::ClosedLoopOptions defaults;
  const std::string kIndent(26, ' ');  // continuation lines of an option's help
  char wear_default[32];
  std::snprintf(wear_default, sizeof wear_default, "%g", defaults.wear_level);
  Options opt("stabilize",
              "Host-sim: the grasp stabiliser in closed loop with the MuJoCo hand (seed paper IV-E). The\n"
              "hand grasps the object (the grasp of the state's Random-2 log, then a 5-step hold); a\n"
              "scripted disturbance then strikes the object while the firmware core (the model compiled\n"
              "into this build) runs every 0.2 s. Two runs on the same grasp and disturbance: without\n"
              "control (u = 0) and with the grasp stabiliser's commands. Reports the evaluation value\n"
              "E = h_loss,1 (N^2: the force channels' squared deviation from the grasp, beta = 3) over\n"
              "time. Deterministic for a seed.",
              "[options]");
  opt.value("object", "NAME", "grasped object: " + plant::object_list(),
            std::string(plant::object_name(defaults.object)));
  opt.value("init", "N", "initialisation (encoder zeroing) id of the grasp's dynamics state",
            std::to_string(defaults.init_id));
  opt.value("wear", "W", "wear level, 0 (new) .. 1 (worn)", wear_default);
  opt.value("seed", "N", "dataset seed (grasp motion and sensor noise derive from it)",
            std::to_string(defaults.seed));
  opt.value("disturbance", "TEXT",
            "none | strike[:FIELD=VALUE,...], fields period=STEPS, duration=STEPS, start=STEP,\n" +
                kIndent + "ramp=STRIKES, force=FX,FY,FZ (N), torque=TX,TY,TZ (N m), drift=DX,DY,DZ (N/step),\n" +
                kIndent + "drift_max=N, frame=world|radial (docs/plant.md); \"strike\" alone is the default\n" +
                kIndent + "schedule " + plant::default_strike().describe(),
            "strike");
  opt.value("periods", "N", "control periods (0.2 s each) after the grasp", std::to_string(defaults.steps));
  opt.value("numeric", "q15|f32", "which generated build of the core", "q15");
  opt.value("pb", "STATE", "PB the stabiliser predicts with: a state name of the model's PB table\n" + kIndent +
                               "(default: <OBJECT>/i0/w0 if the table has it, else the model's default PB)");
  opt.value("control-epochs", "N", "stabiliser epochs (default: the model's)");
  opt.value("control-truncation", "K", "stabiliser truncation depth K (default: the model's)");
  opt.value("csv", "FILE",
            "per step: step, force_N (strike force during the step leading to it),\n" + kIndent +
                "E_without_N2, E_with_N2, contact_without, contact_with (the firmware's flag),\n" + kIndent +
                "d_without, d_with, cmd_<u> (the controlled run's commands, mm); no *_without\n" + kIndent +
                "columns with --only-control");
  opt.value("plot", "PNG", "draw E of both runs with the strike force, and the controlled run's commands");
  opt.repeated("effect", "NAME[=V]", "in the plant (both runs): " + plant::effect_arg_help(kIndent));
  opt.flag("only-control", "skip the run without control");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (!opt.positional().empty()) {
    std::fprintf(stderr, "hadynet stabilize: unexpected argument '%s' (see --help)\n", opt.positional()[0].c_str());
    return 2;
  }

  hostsim::ClosedLoopOptions co;
  const auto object = plant::parse_object(opt.get("object"));
  if (!object) {
    std::fprintf(stderr, "hadynet stabilize: --object: unknown object '%s'\n", opt.get("object").c_str());
    return 2;
  }
  co.object = *object;
  const auto init = opt.get_int("init", 0, 1000);
  const auto wear = opt.get_double("wear", 0.0, 1.0);
  const auto seed = opt.get_int("seed", 0, (1LL << 62));
  const auto steps = opt.get_int("periods", 1, 100000);
  if (!init || !wear || !seed || !steps) return 2;
  co.init_id = static_cast<int>(*init);
  co.wear_level = *wear;
  co.seed = static_cast<std::uint64_t>(*seed);
  co.steps = static_cast<int>(*steps);
  const std::string error = plant::parse_disturbance(opt.get("disturbance"), co.disturbance);
  if (!error.empty()) {
    std::fprintf(stderr, "hadynet stabilize: --disturbance: %s\n", error.c_str());
    return 2;
  }
  for (const auto& e : opt.all("effect")) {
    if (const std::string err = plant::apply_effect_arg(e, co.effects); !err.empty()) {
      std::fprintf(stderr, "hadynet stabilize: --effect: %s\n", err.c_str());
      return 2;
    }
  }
  const auto numeric = opt.get_numeric("numeric");
  if (!numeric) return 2;
  co.numeric = *numeric;
  if (opt.has("control-epochs")) {
    const auto v = opt.get_int("control-epochs", 0, 100);
    if (!v) return 2;
    co.control_epochs = static_cast<int>(*v);
  }
  if (opt.has("control-truncation")) {
    const auto v = opt.get_int("control-truncation", 1, 1000);
    if (!v) return 2;
    co.control_truncation = static_cast<int>(*v);
  }

  // The PB: an explicit state must be in the compiled model's table (which
  // table this build has is a run-time fact, so a miss is a failure, not a
  // usage error); by default the object's first trained state if present.
  const hostsim::CompiledModelInfo info = hostsim::compiled_model_info(co.numeric);
  const auto has_state = [&](const std::string& name) {
    for (const auto& s : info.state_names)
      if (s == name) return true;
    return false;
  };
  std::string pb_note;
  if (opt.has("pb")) {
    co.pb_state = opt.get("pb");
    if (!has_state(co.pb_state)) {
      std::string states;
      for (const auto& s : info.state_names) states += (states.empty() ? "" : ", ") + s;
      std::fprintf(stderr, "hadynet stabilize: --pb: '%s' is not a state of the compiled model's PB table (%s)\n",
                   co.pb_state.c_str(), states.c_str());
      return 1;
    }
    pb_note = co.pb_state + " (--pb)";
  } else {
    plant::ExperimentSpec first_state;  // the object's state at initialisation 0, no wear
    first_state.object = co.object;
    const std::string preferred = plant::state_id(first_state);
    if (has_state(preferred)) {
      co.pb_state = preferred;
      pb_note = preferred + " (default for " + std::string(plant::object_name(co.object)) + ")";
    } else {
      pb_note = "the model's default (" + preferred + " is not in its table)";
    }
  }

  plant::ExperimentSpec state;
  state.object = co.object;
  state.init_id = co.init_id;
  state.wear_level = co.wear_level;
  state.seed = co.seed;
  const std::string state_name = plant::state_id(state);
  const bool only_control = opt.has("only-control");

  try {
    std::optional<hostsim::ClosedLoopRun> without;
    if (!only_control) {
      hostsim::ClosedLoopOptions hold = co;
      hold.control = false;
      without = hostsim::run_closed_loop(hold);
    }
    co.control = true;
    const hostsim::ClosedLoopRun with = hostsim::run_closed_loop(co);
    const hostsim::ClosedLoopRun* without_ptr = without ? &*without : nullptr;

    if (opt.has("csv")) {
      std::FILE* f = std::fopen(opt.get("csv").c_str(), "w");
      if (f == nullptr) throw std::runtime_error(opt.get("csv") + ": cannot write");
      write_csv(f, without_ptr, with);
      const bool failed = std::ferror(f) != 0;
      if (std::fclose(f) != 0 || failed) throw std::runtime_error(opt.get("csv") + ": cannot write");
    }

    // Rows are steps since the grasp (row 0: E = 0 by definition).
    const std::size_t n = static_cast<std::size_t>(co.steps);
    const Window early{1, std::min<std::size_t>(20, n) + 1};
    const Window late{n / 2 + 1, n + 1};
    std::printf("stabilize: %s, seed %llu, %s, %d steps of 0.2 s; PB: %s\n", state_name.c_str(),
                static_cast<unsigned long long>(co.seed), firmware::numeric_name(co.numeric), co.steps, pb_note.c_str());
    std::printf("disturbance: %s\n", co.disturbance.describe().c_str());
    if (co.effects.any()) std::printf("plant effects: %s\n", co.effects.describe().c_str());
    std::printf("mean E [N^2]         %14s %14s\n", early.label().c_str(), late.label().c_str());
    if (without)
      std::printf("  without control    %14.3f %14.3f\n", without->mean_error(early.begin, early.end),
                  without->mean_error(late.begin, late.end));
    const double with_early = with.mean_error(early.begin, early.end);
    const double with_late = with.mean_error(late.begin, late.end);
    std::printf("  with stabiliser    %14.3f %14.3f\n", with_early, with_late);
    if (without) {
      const auto ratio = [](double a, double b) {
        return b > 0.0 ? a / b : std::numeric_limits<double>::quiet_NaN();
      };
      std::printf("  ratio with/without %14.3f %14.3f\n",
                  ratio(with_early, without->mean_error(early.begin, early.end)),
                  ratio(with_late, without->mean_error(late.begin, late.end)));
    }
    if (opt.has("csv")) std::printf("per-step results -> %s\n", opt.get("csv").c_str());

    if (opt.has("plot")) {
      const std::string title = "stabilize: " + state_name + " seed " + std::to_string(co.seed) + " (" + firmware::numeric_name(co.numeric) +
                                "), PB " + (co.pb_state.empty() ? std::string("default") : co.pb_state) + ", " +
                                co.disturbance.describe();
      const std::string err = stabilize_plot(without_ptr, with, title, opt.get("plot"));
      if (!err.empty()) {
        std::fprintf(stderr, "hadynet stabilize: %s\n", err.c_str());
        return 1;
      }
      std::printf("plot -> %s\n", opt.get("plot").c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet stabilize: %s\n", error_text(e).c_str());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
