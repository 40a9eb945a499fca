// Benchmark (not a test): host-sim throughput of the firmware core with the
// build's generated model, q15 and f32, and the MAC counts of its jobs.
// Baseline, measured in the same run: the trainer's Eigen float forward of
// the same detection window (batch of one window). Usage:
//   build/release/host-sim/bench_firmware [--seconds S]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/mac_count.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "trainer/hadynet_network.h"
#include "trainer/model_file.h"

namespace {

using Clock = std::chrono::steady_clock;

std::string cpu_name() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

// Calls f() repeatedly for about `seconds`; returns calls per second.
template <class Fn>
double rate(double seconds, Fn&& f) {
  long calls = 0;
  const auto start = Clock::now();
  double elapsed = 0;
  do {
    for (int i = 0; i < 8; ++i) f();
    calls += 8;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  } while (elapsed < seconds);
  return static_cast<double>(calls) / elapsed;
}

template <class M>
void fill(int t, hadynet::firmware::SensorFrame<M>& f) {
  for (int i = 0; i < M::kY; ++i)
    f.y[i] = M::kYMean[i] + M::kYStd[i] * 0.5f * std::sin(0.37f * static_cast<float>(t + 3 * i));
  for (int i = 0; i < M::kU; ++i) f.u_prev[i] = M::kUStd[i] * 0.3f * std::cos(0.21f * static_cast<float>(t + i));
}

template <class M>
struct Rates {
  double step = 0, detect = 0, control = 0;
};

template <class M>
Rates<M> measure(double seconds) {
  using namespace hadynet::firmware;
  Rates<M> r;
  {
    static HadynetNet<M> net;
    typename M::Value x[M::kX] = {}, pb[M::kPb] = {}, u[M::kU] = {}, y[M::kY];
    net.encode(x, pb);
    r.step = rate(seconds, [&] {
      net.step(u, y);
      u[0] = y[0];  // keep the compiler from hoisting the work
    });
  }
  auto rt = std::make_unique<HadynetRuntime<M>>();
  SensorFrame<M> frame{};
  int t = 0;
  rt->set_mode(Mode::kDetect);
  r.detect = rate(seconds, [&] {
    fill<M>(t++, frame);
    (void)rt->step(frame);
  });
  rt->set_mode(Mode::kControl);
  r.control = rate(seconds, [&] {
    fill<M>(t++, frame);
    (void)rt->step(frame);
  });
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 1.0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      std::puts("usage: bench_firmware [--seconds S]\n\nHost-sim throughput of the firmware core (the build's"
                " generated model, q15 and f32)\nand MAC counts; baseline: the trainer's Eigen float forward of"
                " one\ndetection window, measured in the same run.");
      return 0;
    }
    if (!std::strcmp(argv[i], "--seconds") && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
    } else {
      std::fprintf(stderr, "bench_firmware: unknown argument '%s' (see --help)\n", argv[i]);
      return 2;
    }
  }
  using Q = hadynet::model_q15::Model;
  using F = hadynet::model_f32::Model;
  using MC = hadynet::firmware::MacCount<Q>;
  std::printf("machine: %s (one thread)\nmodel: %s, hash %016llx\n\n", cpu_name().c_str(), Q::kGeneratorVersion,
              static_cast<unsigned long long>(Q::kModelHash));
  std::printf("MACs: HADYNET step %ld (LSTM %ld + decoder %ld), encoder %ld\n", MC::step, MC::lstm_step,
              MC::decode, MC::encode);
  std::printf("      detection (N_detect %d) %ld; stabiliser (horizon %d, %d epochs x %d step sizes, K %d) %ld;\n",
              Q::kDetectSteps, MC::detect, Q::kControlHorizon, Q::kControlEpochs, Q::kControlAlphaCount,
              Q::kControlTruncation, MC::control_default);
  std::printf("      control period (detection + stabiliser) %ld; stabiliser with K = 1: %ld\n",
              MC::period_control, MC::control(Q::kControlEpochs, 1));
  std::printf("RAM: the whole runtime object (network state, history, stabiliser traces): q15 %zu bytes, "
              "f32 %zu bytes\n\n",
              sizeof(hadynet::firmware::HadynetRuntime<Q>), sizeof(hadynet::firmware::HadynetRuntime<F>));

  // Baseline: the trainer's Eigen float forward of one detection window.
  const hadynet::trainer::HadynetModel model = hadynet::trainer::load_model(HADYNET_MODEL_PATH);
  hadynet::trainer::WindowBatch<float> batch;
  batch.x0 = Eigen::MatrixXf::Zero(model.params.dims.x, 1);
  batch.u = Eigen::MatrixXf::Zero(model.params.dims.u, Q::kDetectSteps);
  batch.pb = Eigen::MatrixXf::Zero(model.params.dims.pb, 1);
  hadynet::trainer::HadynetNetwork<float> net;
  const double eigen_rate = rate(seconds, [&] { (void)net.forward(model.params, batch, hadynet::trainer::BnMode::kEval); });

  const Rates<Q> q = measure<Q>(seconds);
  const Rates<F> f = measure<F>(seconds);
  std::printf("%-34s %14s %14s %12s\n", "job", "per second", "MMAC/s", "vs baseline");
  auto row = [&](const char* name, double per_s, long macs) {
    std::printf("%-34s %14.1f %14.1f %11.2fx\n", name, per_s, per_s * static_cast<double>(macs) / 1e6,
                per_s * static_cast<double>(macs) / (eigen_rate * static_cast<double>(MC::detect)));
  };
  row("baseline: Eigen float window", eigen_rate, MC::detect);
  row("q15 HADYNET step", q.step, MC::step);
  row("q15 period, detect mode", q.detect, MC::detect);
  row("q15 period, control mode", q.control, MC::period_control);
  row("f32 HADYNET step", f.step, MC::step);
  row("f32 period, detect mode", f.detect, MC::detect);
  row("f32 period, control mode", f.control, MC::period_control);
  std::printf("\n'vs baseline' = MAC throughput relative to the Eigen float forward. Control mode: worst-case\n"
              "MACs (no early stop). Real time needs >= 5 control periods per second.\n");
  return 0;
}
