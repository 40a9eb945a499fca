// The firmware runtime with the build's generated model: fixed-point edge
// cases (saturation, never overflow or wrap, at extreme inputs), malformed
// sensor values, mode and PB handling, and determinism (bit-identical runs).
// Run under the debug preset too, where UBSan turns any signed overflow into
// a failure.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>

#include "firmware/core/boundary.h"
#include "firmware/core/hadynet_net.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/isqrt.h"
#include "hadynet_model_f32.h"
#include "hadynet_model_q15.h"

namespace hadynet {
namespace {

using Q = model_q15::Model;
using F = model_f32::Model;
using firmware::Boundary;
using firmware::HadynetNet;
using firmware::HadynetRuntime;

TEST(Isqrt, ExactFloorAndRoundedRoots) {
  for (std::uint64_t r : {0ull, 1ull, 2ull, 3ull, 1000ull, 65535ull, 65536ull, 4294967295ull}) {
    EXPECT_EQ(fixed::isqrt_u64(r * r), r);
    if (r > 0) {
      EXPECT_EQ(fixed::isqrt_u64(r * r - 1), r - 1);
    }
    EXPECT_EQ(fixed::isqrt_round_u64(r * r + r), r);      // below (r + 1/2)^2
    EXPECT_EQ(fixed::isqrt_round_u64(r * r + r + 1), r == 4294967295ull ? r : r + 1);
  }
  EXPECT_EQ(fixed::isqrt_u64(std::numeric_limits<std::uint64_t>::max()), 4294967295u);
}

// Physical values far outside anything measured saturate into the formats.
TEST(FirmwareEdgeCases, BoundaryConversionSaturatesAndMapsNaNToTheMean) {
  float y[Q::kY];
  Q::Value v[Q::kY];
  for (float extreme : {1e30f, -1e30f, std::numeric_limits<float>::infinity(),
                        -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()}) {
    for (float& e : y) e = extreme;
    Boundary<Q>{}.y_to_model(y, v);
    for (int i = 0; i < Q::kY; ++i) {
      if (std::isnan(extreme)) {
        EXPECT_EQ(v[i], 0);  // NaN -> 0 standardised = the channel mean
      } else {
        EXPECT_EQ(v[i], extreme > 0 ? 32767 : -32768) << "channel " << i << " extreme " << extreme;
      }
    }
  }
}

// Extreme inputs: every q15 value saturates at a rail with the sign the f32
// build computes, never wraps to the other sign.
TEST(FirmwareEdgeCases, NetworkSaturatesInsteadOfOverflowing) {
  HadynetNet<Q> q;
  HadynetNet<F> f;
  for (int sign : {1, -1}) {
    Q::Value xq[Q::kX], pq[Q::kPb], uq[Q::kU], yq[Q::kY];
    F::Value xf[F::kX], pf[F::kPb], uf[F::kU], yf[F::kY];
    // Alternate the rails so that the products do not cancel.
    for (int i = 0; i < Q::kX; ++i) {
      xq[i] = (i % 2 ? sign : -sign) > 0 ? 32767 : -32768;
      xf[i] = firmware::Numerics<Q>::to_real<Q::kFracIn>(xq[i]);
    }
    for (int i = 0; i < Q::kPb; ++i) {
      pq[i] = sign > 0 ? 32767 : -32768;
      pf[i] = firmware::Numerics<Q>::to_real<Q::kFracIn>(pq[i]);
    }
    for (int i = 0; i < Q::kU; ++i) {
      uq[i] = sign > 0 ? -32768 : 32767;
      uf[i] = firmware::Numerics<Q>::to_real<Q::kFracIn>(uq[i]);
    }
    q.encode(xq, pq);
    f.encode(xf, pf);
    for (int step = 0; step < 5; ++step) {
      q.step(uq, yq);
      f.step(uf, yf);
    }
    const float rail = firmware::Numerics<Q>::to_real<Q::kFracY>(32767);
    int saturated = 0;
    for (int i = 0; i < Q::kY; ++i) {
      const float yr = firmware::Numerics<Q>::to_real<Q::kFracY>(yq[i]);
      if (std::abs(yf[i]) > 1.05f * rail) {
        ++saturated;
        EXPECT_EQ(yq[i], yf[i] > 0 ? 32767 : -32768) << "channel " << i;
      } else if (std::abs(yf[i]) < 0.5f * rail) {
        // A wrapped value would be ~2 rails away.
        EXPECT_LT(std::abs(yr - yf[i]), 0.5f * rail) << "channel " << i;
      }
    }
    std::printf("sign %+d: %d of %d outputs beyond the Q(%d) range, all at the right rail\n", sign, saturated,
                Q::kY, Q::kFracY);
    for (int j = 0; j < Q::kHidden; ++j) {
      // h = o tanh(c): |h| < 1 always, whatever the inputs.
      EXPECT_LE(std::abs(firmware::Numerics<Q>::to_real<Q::kFracH>(q.hidden()[j])), 1.0f);
    }
  }
}

// rollout() is step() repeated: same outputs, same final state.
TEST(FirmwareNet, RolloutEqualsRepeatedSteps) {
  HadynetNet<Q> a, b;
  Q::Value x[Q::kX] = {}, u[4][Q::kU] = {}, ya[4][Q::kY], yb[Q::kY];
  for (int i = 0; i < Q::kX; ++i) x[i] = static_cast<Q::Value>(100 * (i % 7) - 300);
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < Q::kU; ++i) u[k][i] = static_cast<Q::Value>(50 * (k + i) - 200);
  a.encode(x, Q::kPbTable[0]);
  b.encode(x, Q::kPbTable[0]);
  a.rollout(u, ya);
  for (int k = 0; k < 4; ++k) {
    b.step(u[k], yb);
    EXPECT_EQ(std::memcmp(ya[k], yb, sizeof yb), 0) << k;
  }
  EXPECT_EQ(std::memcmp(a.hidden(), b.hidden(), sizeof(Q::Value) * Q::kHidden), 0);
}

// Malformed sensor values reach no undefined behaviour and produce finite,
// flagged results; the runtime keeps working on good frames afterwards.
TEST(FirmwareEdgeCases, RuntimeSurvivesGarbageFrames) {
  auto rt = std::make_unique<HadynetRuntime<Q>>();
  rt->set_mode(firmware::Mode::kControl);
  firmware::SensorFrame<Q> frame{};
  const float garbage[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                           -1e30f, 1e30f, 0.0f};
  for (int t = 0; t < 20; ++t) {
    for (int i = 0; i < Q::kY; ++i) frame.y[i] = garbage[(t + i) % 5];
    for (int i = 0; i < Q::kU; ++i) frame.u_prev[i] = garbage[(t + 2 * i) % 5];
    const auto r = rt->step(frame);
    for (float v : r.prediction) EXPECT_TRUE(std::isfinite(v));
    for (float v : r.command) EXPECT_TRUE(std::isfinite(v));
    EXPECT_TRUE(std::isfinite(r.d));
  }
  for (int i = 0; i < Q::kY; ++i) frame.y[i] = Q::kYMean[i];
  for (int i = 0; i < Q::kU; ++i) frame.u_prev[i] = 0.0f;
  for (int t = 0; t < Q::kDetectSteps + 2; ++t) rt->step(frame);
  const auto r = rt->step(frame);
  EXPECT_TRUE(r.prediction_valid && r.command_valid && r.distance_valid);
}

TEST(FirmwareRuntime, PbStateOutOfRangeIsRejectedAndLeavesThePb) {
  auto rt = std::make_unique<HadynetRuntime<Q>>();
  Q::Value before[Q::kPb];
  std::memcpy(before, rt->pb(), sizeof before);
  EXPECT_FALSE(rt->set_pb_state(-1));
  EXPECT_FALSE(rt->set_pb_state(Q::kStates));
  EXPECT_EQ(std::memcmp(before, rt->pb(), sizeof before), 0);
  ASSERT_GT(Q::kStates, 0);
  EXPECT_TRUE(rt->set_pb_state(Q::kStates - 1));
  EXPECT_EQ(std::memcmp(Q::kPbTable[Q::kStates - 1], rt->pb(), sizeof before), 0);
}

// Results are valid exactly from the frames the contract says.
TEST(FirmwareRuntime, ResultsBecomeValidWhenTheHistoryAllows) {
  auto rt = std::make_unique<HadynetRuntime<F>>();
  rt->set_mode(firmware::Mode::kControl);
  firmware::SensorFrame<F> frame{};
  for (int i = 0; i < F::kY; ++i) frame.y[i] = F::kYMean[i];
  for (int t = 0; t < F::kDetectSteps + 3; ++t) {
    const auto r = rt->step(frame);
    EXPECT_EQ(r.prediction_valid, t >= F::kDetectSteps + 1) << t;
    EXPECT_EQ(r.distance_valid, F::kHasDetection && t >= F::kDetectSteps + 1) << t;
    EXPECT_EQ(r.command_valid, t >= 1) << t;
  }
  rt->set_mode(firmware::Mode::kObserve);
  const auto r = rt->step(frame);
  EXPECT_TRUE(r.prediction_valid);
  EXPECT_FALSE(r.distance_valid);
  EXPECT_FALSE(r.command_valid);
}

template <class M>
std::vector<firmware::StepResult<M>> run_sequence() {
  auto rt = std::make_unique<HadynetRuntime<M>>();
  rt->set_mode(firmware::Mode::kControl);
  std::vector<firmware::StepResult<M>> out;
  firmware::SensorFrame<M> frame{};
  for (int t = 0; t < 30; ++t) {
    for (int i = 0; i < M::kY; ++i)
      frame.y[i] = M::kYMean[i] + M::kYStd[i] * 0.3f * std::sin(0.7f * static_cast<float>(t + i));
    for (int i = 0; i < M::kU; ++i) frame.u_prev[i] = M::kUStd[i] * 0.2f * std::cos(0.3f * static_cast<float>(t * i));
    out.push_back(rt->step(frame));
  }
  return out;
}

template <class M>
void expect_bit_identical() {
  const auto a = run_sequence<M>();
  const auto b = run_sequence<M>();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t t = 0; t < a.size(); ++t) {
    EXPECT_EQ(std::memcmp(a[t].prediction, b[t].prediction, sizeof a[t].prediction), 0) << t;
    EXPECT_EQ(std::memcmp(a[t].command, b[t].command, sizeof a[t].command), 0) << t;
    EXPECT_EQ(std::memcmp(&a[t].d, &b[t].d, sizeof a[t].d), 0) << t;
  }
}

TEST(FirmwareRuntime, BitIdenticalAcrossRuns) {
  expect_bit_identical<Q>();
  expect_bit_identical<F>();
}

}  // namespace
}  // namespace hadynet
