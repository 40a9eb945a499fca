// Benchmark (not a test) of the grasp stabiliser's design on the plant:
// (1) ablation: the closed loop (q15, default strikes, 100 steps) on six
// grasps with the firmware's choices and with each of the paper-literal
// alternatives (grasp_stabilizer.h); (2) the truncation depth K. For each K: multiply-accumulates per control period, the host time
// per period (q15), the direction of the first gradient against full BPTT
// (cosine, f32 core, windows of a held-out plant grasp log) and the closed
// loop on the plant (q15, Cylinder init 3, default strikes): mean E over
// steps 51..100 against no control. Usage:
//   build/release/host-sim/bench_stabilizer
#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <iterator>
#include <string>
#include <memory>
#include <vector>

#include "firmware/core/boundary.h"
#include "firmware/core/grasp_stabilizer.h"
#include "firmware/core/mac_count.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "host-sim/closed_loop/closed_loop.h"
#include "host-sim/plant/experiment.h"

namespace {

using F = hadynet::model_f32::Model;
using Q = hadynet::model_q15::Model;

// First-epoch directions g/|g| (F::kControlHorizon x kU, flattened) of the
// f32 stabiliser at row t of `log` with reference row t - 6, depth K.
std::vector<float> direction(const hadynet::datalog::LogTable& log, const std::vector<std::size_t>& y_cols, int t,
                             int truncation) {
  using namespace hadynet::firmware;
  using B = Boundary<F>;
  static GraspStabilizer<F> stab;
  static HadynetNet<F> net;
  float yt[F::kY], yp[F::kY], yr[F::kY], hold_phys[F::kU] = {};
  for (int i = 0; i < F::kY; ++i) {
    yt[i] = static_cast<float>(log.at(static_cast<std::size_t>(t), y_cols[static_cast<std::size_t>(i)]));
    yp[i] = static_cast<float>(log.at(static_cast<std::size_t>(t - 1), y_cols[static_cast<std::size_t>(i)]));
    yr[i] = static_cast<float>(log.at(static_cast<std::size_t>(t - 6), y_cols[static_cast<std::size_t>(i)]));
  }
  F::Value x[F::kX], y_now[F::kY], y_ref[F::kY], hold[F::kU], u[F::kU];
  B{}.x_from_frames(yt, yp, x);
  B{}.y_to_model(yt, y_now);
  B{}.y_to_model(yr, y_ref);
  B{}.u_to_model(hold_phys, hold);
  stab.reset(hold);
  stab.set_reference(y_ref);
  stab.settings().epochs = 1;
  stab.settings().truncation = truncation;
  stab.plan(net, x, y_now, F::kDetectPb, u);
  std::vector<float> d;
  for (int k = 0; k < F::kControlHorizon; ++k)
    for (int i = 0; i < F::kU; ++i) d.push_back(stab.first_direction(k, i));
  return d;
}

double cosine(const std::vector<float>& a, const std::vector<float>& b) {
  double ab = 0, aa = 0, bb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ab += double{a[i]} * b[i];
    aa += double{a[i]} * a[i];
    bb += double{b[i]} * b[i];
  }
  return aa > 0 && bb > 0 ? ab / std::sqrt(aa * bb) : 1.0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h"))) {
    std::puts("usage: bench_stabilizer\n\nThe grasp stabiliser on the plant: an ablation of its design choices and the cost\n"
              "and accuracy of its truncation depth K (MACs, host time, gradient direction\n"
              "against full BPTT, closed-loop E).");
    return 0;
  }
  hadynet::plant::ExperimentSpec spec;
  spec.object = hadynet::plant::ObjectKind::kCylinder;
  spec.motion = hadynet::plant::Motion::kRandom2;
  spec.init_id = 3;
  spec.steps = 150;
  const hadynet::datalog::LogTable log = hadynet::plant::run_experiment(spec).log;
  std::vector<std::size_t> y_cols;
  for (int i = 0; i < F::kY; ++i) y_cols.push_back(*log.column_index(F::kYNames[i]));

  // ---- (1) ablation
  struct Scenario {
    hadynet::plant::ObjectKind object;
    int init;
    const char* pb;
    bool disturbed;
  };
  using hadynet::plant::ObjectKind;
  const Scenario scenarios[] = {{ObjectKind::kCylinder, 3, "Cylinder/i0/w0", true},
                                {ObjectKind::kCylinder, 1, "Cylinder/i1/w0", true},
                                {ObjectKind::kCylinder, 2, "Cylinder/i2/w0", true},
                                {ObjectKind::kBall, 3, "Ball/i0/w0", true},
                                {ObjectKind::kHammerSoft, 2, "Hammer-S/i2/w0", true},
                                {ObjectKind::kCylinder, 0, "Cylinder/i0/w0", false}};
  struct Variant {
    const char* name;
    bool absolute, adopt_always, all_commands;
  };
  const Variant variants[] = {{"firmware default", false, false, false},
                              {"paper reference r = y_ref", true, false, false},
                              {"paper rule: adopt best alpha", false, true, false},
                              {"all 8 commands", false, false, true},
                              {"all three paper-literal", true, true, true}};
  std::printf("(1) mean E (N^2) over steps 51..100 with control / without, q15; disturbance: default strikes\n");
  std::printf("%-30s", "variant");
  for (const Scenario& sc : scenarios)
    std::printf(" %16s", (std::string(sc.pb).substr(0, std::string(sc.pb).find('/')) + " i" +
                          std::to_string(sc.init) + (sc.disturbed ? "" : " calm"))
                             .c_str());
  std::printf("\n");
  std::vector<double> e_without;
  for (const Scenario& sc : scenarios) {
    hadynet::hostsim::ClosedLoopOptions o;
    o.object = sc.object;
    o.init_id = sc.init;
    o.pb_state = sc.pb;
    o.control = false;
    if (!sc.disturbed) o.disturbance = hadynet::plant::Disturbance{};
    e_without.push_back(hadynet::hostsim::run_closed_loop(o).mean_error(51, 101));
  }
  std::printf("%-30s", "no control");
  for (double e : e_without) std::printf(" %16.2f", e);
  std::printf("\n");
  for (const Variant& v : variants) {
    std::printf("%-30s", v.name);
    for (std::size_t i = 0; i < std::size(scenarios); ++i) {
      const Scenario& sc = scenarios[i];
      hadynet::hostsim::ClosedLoopOptions o;
      o.object = sc.object;
      o.init_id = sc.init;
      o.pb_state = sc.pb;
      if (!sc.disturbed) o.disturbance = hadynet::plant::Disturbance{};
      o.absolute_reference = v.absolute;
      o.adopt_best_always = v.adopt_always;
      o.all_commands = v.all_commands;
      const double e = hadynet::hostsim::run_closed_loop(o).mean_error(51, 101);
      char cell[32];
      std::snprintf(cell, sizeof cell, "%.1f (%.2fx)", e, e / e_without[i]);
      std::printf(" %16s", cell);
    }
    std::printf("\n");
    std::fflush(stdout);
  }
  std::printf("\n(2) truncation depth K\n");

  hadynet::hostsim::ClosedLoopOptions base;
  base.pb_state = "Cylinder/i0/w0";
  base.control = false;
  const double e_none = hadynet::hostsim::run_closed_loop(base).mean_error(51, 101);
  std::printf("held-out grasp log Cylinder random2 init 3 (gradient windows t = 12, 21, ..); closed loop: Cylinder "
              "init 3, PB Cylinder/i0/w0, default strikes; no control: mean E %.2f N^2 (steps 51..100)\n\n",
              e_none);
  std::printf("%3s %14s %12s %16s %16s %12s\n", "K", "MACs/period", "vs full", "q15 ms/period", "cos min (mean)",
              "E ratio");
  using MC = hadynet::firmware::MacCount<Q>;
  const long full = MC::control(Q::kControlEpochs, Q::kControlHorizon);
  for (int k : {1, 2, 3, 4, 6, 8}) {
    double cmin = 1, csum = 0;
    int n = 0;
    for (int t = 12; t + 1 < static_cast<int>(log.rows()); t += 9) {
      const double c = cosine(direction(log, y_cols, t, k), direction(log, y_cols, t, Q::kControlHorizon));
      cmin = std::min(cmin, c);
      csum += c;
      ++n;
    }
    hadynet::hostsim::ClosedLoopOptions o = base;
    o.control = true;
    o.control_truncation = k;
    const auto start = std::chrono::steady_clock::now();
    const auto run = hadynet::hostsim::run_closed_loop(o);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() /
                      static_cast<double>(run.steps.size());
    std::printf("%3d %14ld %11.2fx %16.3f %9.4f (%.4f) %12.2f\n", k, MC::control(Q::kControlEpochs, k),
                static_cast<double>(MC::control(Q::kControlEpochs, k)) / static_cast<double>(full), ms, cmin,
                csum / n, run.mean_error(51, 101) / e_none);
  }
  std::printf("\nms/period: the whole closed-loop step (plant physics included) on this host, one thread.\n");
  return 0;
}
