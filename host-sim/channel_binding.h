// How a compiled model's channels are found, by name, in a source that names
// its own (a log's columns, the plant's observed channels and commands): THE
// binding of replay (host-sim/replay) and the closed loop
// (host-sim/closed_loop), so that both feed the firmware the same frame from
// the same data.
//
// A derived input (M::kUDerived: sign_u0, hyst_u0, ...) is never read from
// the source: the firmware computes it from its base command
// (firmware/core/sensor_stage.h) and ignores what the frame holds, so the
// frame carries 0 for it.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/model_contract.h"

namespace hadynet::hostsim {

struct ChannelBinding {
  static constexpr std::size_t kComputed = static_cast<std::size_t>(-1);  // a derived input
  std::vector<std::size_t> y;  // source index of model y channel i
  std::vector<std::size_t> u;  // source index of model command i, or kComputed
};

// Binds M's channels to `source_y` and `source_u` (for a log, both are its
// columns). Throws std::runtime_error "<source>: no <y_noun|u_noun>
// '<name>', which the compiled model reads" (a log: "column"; the plant:
// "channel", "command").
template <firmware::GeneratedModel M>
ChannelBinding bind_channels(const std::vector<std::string>& source_y, const std::vector<std::string>& source_u,
                             const std::string& source, const char* y_noun, const char* u_noun) {
  const auto index_of = [&](const std::vector<std::string>& names, const char* name, const char* what) {
    for (std::size_t k = 0; k < names.size(); ++k)
      if (names[k] == name) return k;
    throw std::runtime_error(source + ": no " + what + " '" + name + "', which the compiled model reads");
  };
  ChannelBinding b;
  for (int i = 0; i < M::kY; ++i) b.y.push_back(index_of(source_y, M::kYNames[i], y_noun));
  for (int i = 0; i < M::kU; ++i) {
    b.u.push_back(M::kUDerived[i] != firmware::DerivedKind::kNone ? ChannelBinding::kComputed
                                                                  : index_of(source_u, M::kUNames[i], u_noun));
  }
  return b;
}

// The frame of one step: y_t from `y(k)` and u_{t-1} from `u_prev(k)`, k a
// source index of the binding (physical units, rounded once to float).
template <firmware::GeneratedModel M, class YValue, class UValue>
void fill_frame(const ChannelBinding& b, YValue&& y, UValue&& u_prev, firmware::SensorFrame<M>& frame) {
  for (int i = 0; i < M::kY; ++i) frame.y[i] = static_cast<float>(y(b.y[static_cast<std::size_t>(i)]));
  for (int i = 0; i < M::kU; ++i) {
    const std::size_t k = b.u[static_cast<std::size_t>(i)];
    frame.u_prev[i] = k == ChannelBinding::kComputed ? 0.0f : static_cast<float>(u_prev(k));
  }
}

}  // namespace hadynet::hostsim
