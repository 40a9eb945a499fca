// On-device PB adaptation (firmware/core/pb_adapter.h) with the build's
// generated model: its PB gradient against the trainer's, q15 against f32,
// what adaptation does to the prediction error of a re-initialised hand,
// saturation, determinism. Tolerances: docs/tolerances.md.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/pb_adapter.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "test/firmware/held_out_logs.h"
#include "trainer/pb_adaptation.h"
#include "trainer/recognition.h"
#include "trainer/window_dataset.h"

namespace hadynet {
namespace {

using Q = model_q15::Model;
using F = model_f32::Model;
using firmware::HadynetNet;
using firmware::PbAdapter;

// Frame t of a log sequence as the firmware sees it: y_t and u_{t-1}.
template <class M, class Adapter>
void push_frame(Adapter& adapter, const trainer::LogSequence& seq, int t) {
  float y[M::kY], u[M::kU] = {};
  for (int i = 0; i < M::kY; ++i) y[i] = static_cast<float>(seq.y(i, t));
  if (t > 0)
    for (int i = 0; i < M::kU; ++i) u[i] = static_cast<float>(seq.u(i, t - 1));
  adapter.push(y, u);
}

template <class M>
std::vector<float> table_pb(int state) {
  std::vector<float> p(M::kPb);
  for (int i = 0; i < M::kPb; ++i) p[static_cast<std::size_t>(i)] = firmware::Numerics<M>::template to_real<M::kFracIn>(
      firmware::kCompiledTensors<M>.pb_table[state][i]);
  return p;
}

// The gradient of the loss of one window (the first of `seq`) w.r.t. the PB,
// from PB table row `state`, by the firmware.
template <class M>
std::vector<float> firmware_window_gradient(const trainer::LogSequence& seq, int state, float* loss) {
  auto adapter = std::make_unique<PbAdapter<M, 1>>();
  auto net = std::make_unique<HadynetNet<M>>();
  std::vector<firmware::StepTrace<M>> traces(M::kTrainSteps);
  typename PbAdapter<M, 1>::Settings s;
  s.start_windows = 1;
  s.windows_per_period = 1;
  EXPECT_TRUE(adapter->set_settings(s));
  adapter->restart(firmware::kCompiledTensors<M>.pb_table[state]);
  for (int t = 0; t < M::kTrainSteps + 2; ++t) push_frame<M>(*adapter, seq, t);
  EXPECT_EQ(adapter->windows_held(), 1);
  EXPECT_TRUE(adapter->work(*net, traces.data()));
  EXPECT_EQ(adapter->updates(), 1u);
  float g[M::kPb];
  adapter->last_gradient(g);
  *loss = adapter->last_loss();
  return std::vector<float>(g, g + M::kPb);
}

// The trainer's gradient of the same window: one MomentumSGD step without
// momentum at a small rate from the same PB, g = (p0 - p1) / lr.
std::vector<float> trainer_window_gradient(const trainer::LogSequence& seq, int state, float* loss) {
  const trainer::HadynetModel& model = test::build_model();
  trainer::LogSequence window = seq;
  window.y = seq.y.leftCols(F::kTrainSteps + 2);
  window.u = seq.u.leftCols(F::kTrainSteps + 2);
  const trainer::WindowDataset data({window}, {0}, model.layout, model.norm, F::kTrainSteps);
  EXPECT_EQ(data.size(), 1);
  const std::vector<float> p0 = table_pb<F>(state);
  const Eigen::VectorXf start = Eigen::Map<const Eigen::VectorXf>(p0.data(), F::kPb);
  constexpr double kLr = 0.05;
  const std::vector<int> ids{0};
  const trainer::AdaptResult r = trainer::adapt_pb(model, data, ids, start, {1, kLr, 0.0});
  EXPECT_EQ(r.halvings, 0);
  *loss = static_cast<float>(r.loss.front());
  std::vector<float> g(F::kPb);
  for (int i = 0; i < F::kPb; ++i) g[static_cast<std::size_t>(i)] = static_cast<float>((start(i) - r.pb(i)) / kLr);
  return g;
}

float max_abs(const std::vector<float>& v) {
  float m = 0.0f;
  for (float x : v) m = std::max(m, std::fabs(x));
  return m;
}

// The firmware's back-propagation through time (decoder, every LSTM step,
// encoder) gives the trainer's PB gradient. Tolerance: 1e-3 of the largest
// entry, float32 sums in another order (the trainer's gradient is read from
// a step of rate 0.05, exact to ~1e-6).
TEST(PbAdapter, WindowGradientEqualsTheTrainers) {
  for (const char* object : {"Cylinder", "Hammer"}) {
    const trainer::LogSequence seq = test::held_out_sequence(object, "random2");
    for (int state : {0, 4}) {
      float loss_fw = 0, loss_tr = 0;
      const std::vector<float> g_fw = firmware_window_gradient<F>(seq, state, &loss_fw);
      const std::vector<float> g_tr = trainer_window_gradient(seq, state, &loss_tr);
      const float scale = max_abs(g_tr);
      ASSERT_GT(scale, 0.0f);
      EXPECT_NEAR(loss_fw, loss_tr, 1e-4 * loss_tr) << object << " state " << state;
      for (int i = 0; i < F::kPb; ++i)
        EXPECT_NEAR(g_fw[static_cast<std::size_t>(i)], g_tr[static_cast<std::size_t>(i)], 1e-3 * scale)
            << object << " state " << state << " PB " << i;
    }
  }
}

// q15's gradient against f32's on the same windows: within 5 % (norm of the
// difference over the norm; measured at most 1.9 % on these nine windows,
// the q15 forward pass's rounding of y and h; docs/tolerances.md, "PB
// adaptation"), losses within 1 %.
TEST(PbAdapter, FixedPointGradientFollowsTheFloatOne) {
  for (const char* object : {"Cylinder", "Hammer", "None"}) {
    const trainer::LogSequence seq = test::held_out_sequence(object, "random2");
    for (int state : {0, 4, 9}) {
      float loss_q = 0, loss_f = 0;
      const std::vector<float> g_q = firmware_window_gradient<Q>(seq, state, &loss_q);
      const std::vector<float> g_f = firmware_window_gradient<F>(seq, state, &loss_f);
      float diff = 0, norm = 0;
      for (int i = 0; i < F::kPb; ++i) {
        const float d = g_q[static_cast<std::size_t>(i)] - g_f[static_cast<std::size_t>(i)];
        diff += d * d;
        norm += g_f[static_cast<std::size_t>(i)] * g_f[static_cast<std::size_t>(i)];
      }
      EXPECT_LT(std::sqrt(diff / norm), 0.05) << object << " state " << state;
      EXPECT_NEAR(loss_q, loss_f, 0.01 * loss_f) << object << " state " << state;
    }
  }
}

// Garbage frames (NaN, infinities, 1e30) while adapting, from the first
// window on: the PB, its loss and its recognition stay finite in both
// numerics, and the q15 build never overflows (UBSan in the debug preset).
template <class M>
void adapt_on_garbage() {
  auto rt = std::make_unique<firmware::HadynetRuntime<M>>();
  typename PbAdapter<M>::Settings s;
  s.start_windows = 1;
  s.windows_per_period = 2;
  ASSERT_TRUE(rt->set_adapt_settings(s));
  rt->set_adapting(true);
  const float garbage[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), -1e30f,
                           1e30f, 0.0f, -std::numeric_limits<float>::infinity()};
  firmware::SensorFrame<M> frame{};
  for (int t = 0; t < 3 * M::kTrainSteps; ++t) {
    for (int i = 0; i < M::kY; ++i) frame.y[i] = garbage[(t + i) % 6];
    for (int i = 0; i < M::kU; ++i) frame.u_prev[i] = garbage[(t + 2 * i) % 6];
    const auto r = rt->step(frame);
    if (r.adapt_valid) {
      EXPECT_TRUE(r.recognition.valid);
      EXPECT_TRUE(std::isfinite(r.recognition.distance) && std::isfinite(r.recognition.other_distance));
    }
    for (int i = 0; i < M::kPb; ++i)
      EXPECT_TRUE(std::isfinite(firmware::Numerics<M>::template to_real<M::kFracIn>(rt->adapter().pb()[i])));
    EXPECT_TRUE(std::isfinite(rt->adapter().last_loss()));
  }
  EXPECT_GT(rt->adapter().updates(), 0u);
}

TEST(PbAdapter, GarbageFramesNeverOverflowOrGiveNaN) {
  adapt_on_garbage<Q>();
  adapt_on_garbage<F>();
}

}  // namespace
}  // namespace hadynet

namespace hadynet {
namespace {

// The mean window loss of `seq` under PB `pb` (standardised), by the trainer.
double trainer_loss(const trainer::LogSequence& seq, const Eigen::VectorXf& pb) {
  const trainer::HadynetModel& model = test::build_model();
  const trainer::WindowDataset data({seq}, {0}, model.layout, model.norm, F::kTrainSteps);
  std::vector<int> ids(static_cast<std::size_t>(data.size()));
  for (int i = 0; i < data.size(); ++i) ids[static_cast<std::size_t>(i)] = i;
  return trainer::adapt_pb(model, data, ids, pb, {0, 1.0, 0.9}).loss.front();
}

template <class M>
Eigen::VectorXf real_pb(const typename M::Value (&pb)[M::kPb]) {
  Eigen::VectorXf p(M::kPb);
  for (int i = 0; i < M::kPb; ++i) p(i) = firmware::Numerics<M>::template to_real<M::kFracIn>(pb[i]);
  return p;
}

// Streams `seq` through a runtime adapting in detect mode; returns the adapted PB.
int g_stride = 1;
template <class M>
Eigen::VectorXf runtime_adapt(const trainer::LogSequence& seq, int* updates, int* recognized) {
  auto rt = std::make_unique<firmware::HadynetRuntime<M>>();
  typename firmware::PbAdapter<M>::Settings s;
  s.window_stride = g_stride;
  EXPECT_TRUE(rt->set_adapt_settings(s));
  rt->set_mode(firmware::Mode::kDetect);
  rt->set_adapting(true);
  firmware::StepResult<M> out;
  for (int t = 0; t < seq.steps(); ++t) {
    firmware::SensorFrame<M> f{};
    for (int i = 0; i < M::kY; ++i) f.y[i] = static_cast<float>(seq.y(i, t));
    if (t > 0)
      for (int i = 0; i < M::kU; ++i) f.u_prev[i] = static_cast<float>(seq.u(i, t - 1));
    out = rt->step(f);
  }
  *updates = static_cast<int>(out.adapt_updates);
  *recognized = out.recognition.valid ? out.recognition.state : -1;
  return real_pb<M>(rt->adapter().pb());
}

TEST(PbAdapterExplore, StreamLowersTheErrorOfAReinitialisedHand) {
  const trainer::HadynetModel& model = test::build_model();
  if (const char* e = std::getenv("STRIDE")) g_stride = std::atoi(e);
  for (const char* object : {"Cylinder", "Hammer", "None", "Ball"}) {
    const trainer::LogSequence stream = test::held_out_sequence(object, "random2", 400);
    const trainer::LogSequence eval = test::held_out_sequence(object, "random1", 150);
    const Eigen::VectorXf stale = real_pb<F>(firmware::kCompiledTensors<F>.detect_pb);
    int uq = 0, uf = 0, rq = -1, rf = -1;
    const Eigen::VectorXf pq = runtime_adapt<Q>(stream, &uq, &rq);
    const Eigen::VectorXf pf = runtime_adapt<F>(stream, &uf, &rf);
    Eigen::VectorXf pt = stale;
    if (std::getenv("ONLINE")) {
      trainer::OnlinePbAdapter online(model, stale, {});
      for (int t = 0; t < stream.steps(); ++t) online.push(stream.y.col(t), stream.u.col(t));
      pt = online.pb();
    }
    std::printf("%s: loss stale %.4f  q15 %.4f (%d steps, state %d)  f32 %.4f (%d, %d)  trainer online %.4f (%s)  |q-f| %.3f |f-t| %.3f\n",
                object, trainer_loss(eval, stale), trainer_loss(eval, pq), uq, rq, trainer_loss(eval, pf), uf, rf,
                trainer_loss(eval, pt), model.states[static_cast<std::size_t>(trainer::nearest_pb(model, pt).state)].name.c_str(),
                (pq - pf).norm(), (pf - pt).norm());
  }
}

}  // namespace
}  // namespace hadynet
