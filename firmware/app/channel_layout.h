// Which of the model's observed channels (y) the board measures itself and
// which ones the host sends: THE one place that maps the generated model's
// channels onto the firmware's 5 Hz loop (period_loop.h).
//
// The rule, from the model's own channel names and robot profile
// (M::kYNames and M::kBoardGroup, written by codegen from the logs' header;
// docs/log-format.md):
//   * y channel "<kBoardGroup><k>" is the board's loadcell k (the hand:
//     "fc3" is reading 3 of board::read_loadcells);
//   * every other y channel is part of the muscle state the host sends over
//     the link (for the hand: l0..l7, f0..f7, th0, th1), in y order;
//   * the muscle state also carries u_{t-1}, all M::kU commands.
// Nothing here knows the hand: the sizes follow from the names at compile
// time, and a model whose board channels are not exactly <group>0 ..
// <group>n-1 fails the build.
#ifndef HADYNET_FIRMWARE_APP_CHANNEL_LAYOUT_H_
#define HADYNET_FIRMWARE_APP_CHANNEL_LAYOUT_H_

#include <array>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_contract.h"

namespace hadynet::app {

// k if `name` is `group` followed by decimal digits only ("fc3" in group
// "fc" -> 3), else -1; always -1 for an empty group (a model whose board
// measures nothing).
constexpr int loadcell_index_of(const char* group, const char* name) noexcept {
  if (group[0] == '\0') return -1;
  int i = 0;
  for (; group[i] != '\0'; ++i) {
    if (name[i] != group[i]) return -1;
  }
  if (name[i] == '\0') return -1;
  int k = 0;
  for (; name[i] != '\0'; ++i) {
    if (name[i] < '0' || name[i] > '9' || k > 100000) return -1;
    k = 10 * k + (name[i] - '0');
  }
  return k;
}

// Number of loadcell channels of model M.
template <firmware::GeneratedModel M>
constexpr int count_loadcell_channels() noexcept {
  int n = 0;
  for (int i = 0; i < M::kY; ++i) n += loadcell_index_of(M::kBoardGroup, M::kYNames[i]) >= 0 ? 1 : 0;
  return n;
}

template <firmware::GeneratedModel M>
struct ChannelLayout {
  // Board (loadcell) channels in the model (9 for the hand) and the other observed
  // channels (18 for the hand: l, f, theta).
  static constexpr int kLoadcells = count_loadcell_channels<M>();
  static constexpr int kMuscleY = M::kY - kLoadcells;
  // Entries of a loadcell array: kLoadcells, at least 1 (as the model
  // contract's arrays; a model without loadcells has one unused 0 entry).
  static constexpr int kLoadcellSlots = kLoadcells > 0 ? kLoadcells : 1;
  static_assert(kMuscleY >= 1, "the model observes nothing but loadcells: no muscle state to receive");

  // y channel of loadcell k ("<kBoardGroup><k>").
  static constexpr std::array<int, kLoadcells> kLoadcellY = [] {
    std::array<int, kLoadcells> out{};
    for (int k = 0; k < kLoadcells; ++k) out[k] = -1;
    for (int i = 0; i < M::kY; ++i) {
      const int k = loadcell_index_of(M::kBoardGroup, M::kYNames[i]);
      if (k >= 0 && k < kLoadcells) out[k] = i;
    }
    return out;
  }();

  // y channel of muscle-state entry j (the non-loadcell channels, y order).
  static constexpr std::array<int, kMuscleY> kMuscleYChannel = [] {
    std::array<int, kMuscleY> out{};
    int j = 0;
    for (int i = 0; i < M::kY; ++i) {
      if (loadcell_index_of(M::kBoardGroup, M::kYNames[i]) < 0) out[j++] = i;
    }
    return out;
  }();

  // Every k in 0..kLoadcells-1 names exactly one channel (no gap, no repeat:
  // n channels and none of 0..n-1 missing).
  static_assert(
      [] {
        for (int k = 0; k < kLoadcells; ++k) {
          if (kLoadcellY[k] < 0) return false;
        }
        return true;
      }(),
      "the model's board channels <kBoardGroup><k> must be exactly <kBoardGroup>0 .. <kBoardGroup>n-1");
};

// The part of one sensor frame that comes over the link: every observed
// channel except the loadcells, and the command applied since t-1.
// Physical (log) units, like firmware::SensorFrame.
template <firmware::GeneratedModel M>
struct MuscleState {
  float y[ChannelLayout<M>::kMuscleY] = {};  // y_t without the loadcells, in y order (l, f, theta)
  float u_prev[M::kU] = {};                  // u_{t-1}
};

// One sensor frame from a muscle state and the loadcells (newtons, loadcell
// k = "<kBoardGroup><k>"). Copies only: the frame holds exactly these bits.
template <firmware::GeneratedModel M>
constexpr void assemble_frame(const MuscleState<M>& muscle,
                              const float (&loadcells_N)[ChannelLayout<M>::kLoadcellSlots],
                              firmware::SensorFrame<M>& frame) noexcept {
  using L = ChannelLayout<M>;
  for (int j = 0; j < L::kMuscleY; ++j) frame.y[L::kMuscleYChannel[j]] = muscle.y[j];
  for (int k = 0; k < L::kLoadcells; ++k) frame.y[L::kLoadcellY[k]] = loadcells_N[k];
  for (int i = 0; i < M::kU; ++i) frame.u_prev[i] = muscle.u_prev[i];
}

// The inverse (host tools and tests): a sensor frame split into what the
// host sends and what the board measures.
template <firmware::GeneratedModel M>
constexpr void split_frame(const firmware::SensorFrame<M>& frame, MuscleState<M>& muscle,
                           float (&loadcells_N)[ChannelLayout<M>::kLoadcellSlots]) noexcept {
  using L = ChannelLayout<M>;
  for (int j = 0; j < L::kMuscleY; ++j) muscle.y[j] = frame.y[L::kMuscleYChannel[j]];
  for (int k = 0; k < L::kLoadcells; ++k) loadcells_N[k] = frame.y[L::kLoadcellY[k]];
  for (int i = 0; i < M::kU; ++i) muscle.u_prev[i] = frame.u_prev[i];
}

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_CHANNEL_LAYOUT_H_
