// On-device PB adaptation (firmware/core/pb_adapter.h) with the build's
// generated model: its PB gradient against the trainer's, q15 against f32,
// what adaptation does to the prediction error of a re-initialised hand,
// saturation, determinism. Tolerances: docs/tolerances.md.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/pb_adapter.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "test/firmware/held_out_logs.h"
#include "test/firmware/tolerances.h"
#include "trainer/pb_adaptation.h"
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
  s.window_stride = 1;
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
// encoder) gives the trainer's PB gradient (docs/tolerances.md, adapt.f32.*).
TEST(PbAdapter, WindowGradientEqualsTheTrainers) {
  double worst_g = 0, worst_loss = 0;
  for (const char* object : {"Cylinder", "Hammer"}) {
    const trainer::LogSequence seq = test::held_out_sequence(object, "random2");
    for (int state : {0, 4}) {
      float loss_fw = 0, loss_tr = 0;
      const std::vector<float> g_fw = firmware_window_gradient<F>(seq, state, &loss_fw);
      const std::vector<float> g_tr = trainer_window_gradient(seq, state, &loss_tr);
      const float scale = max_abs(g_tr);
      ASSERT_GT(scale, 0.0f);
      const double loss_rel = std::fabs(loss_fw - loss_tr) / loss_tr;
      double g_rel = 0;
      for (int i = 0; i < F::kPb; ++i)
        g_rel = std::max(g_rel, static_cast<double>(std::fabs(g_fw[static_cast<std::size_t>(i)] -
                                                              g_tr[static_cast<std::size_t>(i)]) / scale));
      EXPECT_LE(loss_rel, test::tolerance("adapt.f32.loss_rel")) << object << " state " << state;
      EXPECT_LE(g_rel, test::tolerance("adapt.f32.gradient_rel")) << object << " state " << state;
      worst_g = std::max(worst_g, g_rel);
      worst_loss = std::max(worst_loss, loss_rel);
    }
  }
  std::printf("f32 window against the trainer: gradient max |diff| / max |g| %.2e, loss relative %.2e\n", worst_g,
              worst_loss);
}

// q15's gradient against f32's on the same windows (docs/tolerances.md,
// adapt.q15.*): |g_q15 - g_f32| / |g_f32| and the losses' relative difference.
TEST(PbAdapter, FixedPointGradientFollowsTheFloatOne) {
  double worst_g = 0, worst_loss = 0;
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
      const double g_rel = std::sqrt(diff / norm), loss_rel = std::fabs(loss_q - loss_f) / loss_f;
      EXPECT_LE(g_rel, test::tolerance("adapt.q15.gradient_rel")) << object << " state " << state;
      EXPECT_LE(loss_rel, test::tolerance("adapt.q15.loss_rel")) << object << " state " << state;
      worst_g = std::max(worst_g, g_rel);
      worst_loss = std::max(worst_loss, loss_rel);
    }
  }
  std::printf("q15 window against f32: gradient |diff| / |g| %.4f, loss relative %.4f\n", worst_g, worst_loss);
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

// An epoch whose snapshot holds no window on the stride (here the only
// window starts at frame 1, the stride is 8) runs nothing and work()
// returns: no endless loop of empty epochs, and later windows still run.
TEST(PbAdapter, AnEpochWithoutWindowsOnTheStrideEndsThePeriod) {
  auto adapter = std::make_unique<PbAdapter<Q>>();
  auto net = std::make_unique<HadynetNet<Q>>();
  std::vector<firmware::StepTrace<Q>> traces(Q::kTrainSteps);
  typename PbAdapter<Q>::Settings s;
  s.start_windows = 1;
  s.windows_per_period = 4;
  s.window_stride = 8;
  ASSERT_TRUE(adapter->set_settings(s));
  adapter->restart(firmware::kCompiledTensors<Q>.pb_table[0]);
  const trainer::LogSequence seq = test::held_out_sequence("Cylinder", "random2");
  push_frame<Q>(*adapter, seq, 0);
  adapter->begin_segment();  // window 0 would span the boundary: the first window starts at frame 1
  for (int t = 1; t < Q::kTrainSteps + 3; ++t) push_frame<Q>(*adapter, seq, t);
  ASSERT_EQ(adapter->windows_held(), 1);
  EXPECT_FALSE(adapter->work(*net, traces.data()));  // returns (the test would hang otherwise)
  EXPECT_EQ(adapter->updates(), 0u);
  for (int t = Q::kTrainSteps + 3; t < Q::kTrainSteps + 12; ++t) push_frame<Q>(*adapter, seq, t);
  EXPECT_TRUE(adapter->work(*net, traces.data()));  // window 8 is on the stride
  EXPECT_GE(adapter->updates(), 1u);  // (an epoch of one window: one step per window of the budget)
}

TEST(PbAdapter, GarbageFramesNeverOverflowOrGiveNaN) {
  adapt_on_garbage<Q>();
  adapt_on_garbage<F>();
}

}  // namespace
}  // namespace hadynet

