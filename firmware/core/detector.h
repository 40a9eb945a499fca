// Contact detection (docs/method.md, "Detection"): the last N_detect + 2 sensor frames in a
// ring buffer, the model's estimate of y_t from x_{t-N} and u_[t-N, t) under
// a PB, and the Mahalanobis distance of its error
//   d = sqrt((e - mu)^T Sigma^-1 (e - mu)) = |W (e - mu)|,  e = y_est - y_t,
// with the whitening matrix W (W^T W = Sigma^-1) from codegen; contact when
// d > C_detect. Standardised units throughout; physical frames in.
#ifndef HADYNET_FIRMWARE_CORE_DETECTOR_H_
#define HADYNET_FIRMWARE_CORE_DETECTOR_H_

#include <cmath>
#include <cstdint>

#include "firmware/core/boundary.h"
#include "firmware/core/hadynet_net.h"
#include "firmware/core/isqrt.h"

namespace hadynet::firmware {

// The last kFrames sensor frames: y_t and the command u_{t-1} applied before
// it, physical units.
template <GeneratedModel M, int kFrames>
class FrameHistory {
 public:
  static_assert(kFrames >= 2, "need y_t and y_{t-1} at least");
  void clear() noexcept { count_ = 0; }
  void push(const float (&y)[M::kY], const float (&u_prev)[M::kU]) noexcept {
    head_ = (head_ + 1) % kFrames;
    for (int i = 0; i < M::kY; ++i) y_[head_][i] = y[i];
    for (int i = 0; i < M::kU; ++i) u_prev_[head_][i] = u_prev[i];
    if (count_ < kFrames) ++count_;
  }
  int count() const noexcept { return count_; }
  // Frame `age` steps ago (0 = newest); age < count().
  const float (&y(int age) const noexcept)[M::kY] { return y_[slot(age)]; }
  const float (&u_prev(int age) const noexcept)[M::kU] { return u_prev_[slot(age)]; }

 private:
  int slot(int age) const noexcept { return (head_ + kFrames - age) % kFrames; }
  float y_[kFrames][M::kY] = {};
  float u_prev_[kFrames][M::kU] = {};
  int head_ = 0;
  int count_ = 0;
};

template <GeneratedModel M>
class Detector {
 public:
  using N = Numerics<M>;
  using Value = typename M::Value;
  using B = Boundary<M>;
  static constexpr int kSteps = M::kDetectSteps;  // N_detect
  static_assert(kSteps >= 1, "N_detect >= 1");
  // y_{t-N-1} .. y_t: x_{t-N} needs y_{t-N} and y_{t-N-1}.
  static constexpr int kFrames = kSteps + 2;
  using History = FrameHistory<M, kFrames>;
  // Squared distance type: q15 int64 in Q(2 kFracZ); f32 float.
  using Distance2 = std::conditional_t<N::kFixed, std::int64_t, float>;

  // True once the history holds N_detect + 2 frames.
  static bool ready(const History& history) noexcept { return history.count() >= kFrames; }

  // y_est_t (Q(kFracY)) from the history under PB `pb`: encode x_{t-N}, run
  // the N recorded commands. Uses (and overwrites) `net`'s state.
  static void estimate(const History& history, const Value (&pb)[M::kPb], HadynetNet<M>& net,
                       Value (&y_est)[M::kY]) noexcept {
    const B boundary(net.tensors());
    Value x[M::kX];
    boundary.x_from_frames(history.y(kSteps), history.y(kSteps + 1), x);
    net.encode(x, pb);
    for (int k = 0; k < kSteps; ++k) {
      Value u[M::kU];
      // u_{t-N+k} was applied before frame t-N+k+1, i.e. the frame of age N-k-1.
      boundary.u_to_model(history.u_prev(kSteps - k - 1), u);
      net.step(u, y_est);
    }
  }

  // |W (e - mu)|^2 for e = y_est - y (both Q(kFracY)), with the detection
  // statistics of `t`.
  static Distance2 distance2(const ModelTensors<M>& t, const Value (&y_est)[M::kY],
                             const Value (&y)[M::kY]) noexcept {
    if constexpr (N::kFixed) {
      std::int32_t centred[M::kY];
      for (int i = 0; i < M::kY; ++i) {
        centred[i] = std::int32_t{y_est[i]} - y[i] - t.detect_mean[i];
      }
      std::int64_t d2 = 0;
      for (int r = 0; r < M::kY; ++r) {
        std::int64_t acc = 0;
        for (int c = 0; c < M::kY; ++c) acc += std::int64_t{t.detect_whiten[r][c]} * centred[c];
        const std::int16_t z = fixed::requantize_i16<M::kFracWhiten + M::kFracY, M::kFracZ>(acc);
        d2 += std::int64_t{z} * z;
      }
      return d2;
    } else {
      float centred[M::kY];
      for (int i = 0; i < M::kY; ++i) centred[i] = y_est[i] - y[i] - t.detect_mean[i];
      float d2 = 0.0f;
      for (int r = 0; r < M::kY; ++r) {
        float z = 0.0f;
        for (int c = 0; c < M::kY; ++c) z += t.detect_whiten[r][c] * centred[c];
        d2 += z * z;
      }
      return d2;
    }
  }

  static bool is_contact(const ModelTensors<M>& t, Distance2 d2) noexcept { return d2 > t.detect_threshold_sq; }

  // d in standardised units (q15: integer square root, then one scaling).
  static float distance(Distance2 d2) noexcept {
    if constexpr (N::kFixed) {
      return static_cast<float>(fixed::isqrt_round_u64(static_cast<std::uint64_t>(d2))) /
             static_cast<float>(std::int64_t{1} << M::kFracZ);
    } else {
      return std::sqrt(d2);
    }
  }
};

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_DETECTOR_H_
