// On-device PB adaptation (firmware/core/pb_adapter.h) with the build's
// generated model: its PB gradient against the trainer's, q15 against f32,
// what adaptation does to the prediction error of a re-initialised hand,
// saturation, determinism. Tolerances: docs/tolerances.md.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/pb_adapter.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"
#include "test/firmware/held_out_logs.h"
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
  typename PbAdapter<M, 1>::Settings s;
  s.start_windows = 1;
  s.windows_per_period = 1;
  EXPECT_TRUE(adapter->set_settings(s));
  adapter->restart(firmware::kCompiledTensors<M>.pb_table[state]);
  for (int t = 0; t < M::kTrainSteps + 2; ++t) push_frame<M>(*adapter, seq, t);
  EXPECT_EQ(adapter->windows_held(), 1);
  EXPECT_TRUE(adapter->work(*net));
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
    const trainer::LogSequence seq = test::held_out_sequence(object, "Random2");
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
    const trainer::LogSequence seq = test::held_out_sequence(object, "Random2");
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

}  // namespace
}  // namespace hadynet
