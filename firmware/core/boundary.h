// Conversions at the core's boundary between physical float32 values (log
// units: what sensors give and actuators take) and the model's standardised
// Values (model_contract.h). Float operations only here, each a single IEEE
// binary32 multiply or add in a fixed order (the firmware is built with
// -ffp-contract=off), so host and MCU convert bit-identically.
#ifndef HADYNET_FIRMWARE_CORE_BOUNDARY_H_
#define HADYNET_FIRMWARE_CORE_BOUNDARY_H_

#include "firmware/core/model_contract.h"
#include "firmware/core/numerics.h"

namespace hadynet::firmware {

template <GeneratedModel M>
struct Boundary {
  using N = Numerics<M>;
  using Value = typename M::Value;

  // x_t from y_t and y_{t-1} (physical): channel i is y[kXSource[i]], or its
  // change since t-1 if kXIsDelta[i]; standardised, Q(kFracIn).
  static void x_from_frames(const float (&y_t)[M::kY], const float (&y_prev)[M::kY],
                            Value (&x)[M::kX]) noexcept {
    for (int i = 0; i < M::kX; ++i) {
      const int s = M::kXSource[i];
      const float raw = M::kXIsDelta[i] ? y_t[s] - y_prev[s] : y_t[s];
      x[i] = N::template from_real<M::kFracIn>((raw - M::kXMean[i]) * M::kXInvStd[i]);
    }
  }
  // Physical y -> standardised, Q(kFracY).
  static void y_to_model(const float (&y)[M::kY], Value (&out)[M::kY]) noexcept {
    for (int i = 0; i < M::kY; ++i) {
      out[i] = N::template from_real<M::kFracY>((y[i] - M::kYMean[i]) * M::kYInvStd[i]);
    }
  }
  // Standardised Q(kFracY) -> physical y.
  static void y_to_physical(const Value (&v)[M::kY], float (&out)[M::kY]) noexcept {
    for (int i = 0; i < M::kY; ++i) {
      out[i] = N::template to_real<M::kFracY>(v[i]) * M::kYStd[i] + M::kYMean[i];
    }
  }
  // Physical command -> standardised, Q(kFracIn).
  static void u_to_model(const float (&u)[M::kU], Value (&out)[M::kU]) noexcept {
    for (int i = 0; i < M::kU; ++i) {
      out[i] = N::template from_real<M::kFracIn>((u[i] - M::kUMean[i]) * M::kUInvStd[i]);
    }
  }
  // Standardised Q(kFracIn) -> physical command.
  static void u_to_physical(const Value (&v)[M::kU], float (&out)[M::kU]) noexcept {
    for (int i = 0; i < M::kU; ++i) {
      out[i] = N::template to_real<M::kFracIn>(v[i]) * M::kUStd[i] + M::kUMean[i];
    }
  }
  // A standardised real vector (e.g. a PB from the link) -> Q(kFracIn).
  template <int Size>
  static void real_to_in(const float (&v)[Size], Value (&out)[Size]) noexcept {
    for (int i = 0; i < Size; ++i) out[i] = N::template from_real<M::kFracIn>(v[i]);
  }
};

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_BOUNDARY_H_
