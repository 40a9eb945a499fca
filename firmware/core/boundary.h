// Conversions at the core's boundary between physical float32 values (log
// units: what sensors give and actuators take) and the model's standardised
// Values (model_contract.h). Float operations only here, each a single IEEE
// binary32 multiply or add in a fixed order (the firmware is built with
// -ffp-contract=off), so host and MCU convert bit-identically.
#ifndef HADYNET_FIRMWARE_CORE_BOUNDARY_H_
#define HADYNET_FIRMWARE_CORE_BOUNDARY_H_

#include "firmware/core/model_contract.h"
#include "firmware/core/model_tensors.h"
#include "firmware/core/numerics.h"

namespace hadynet::firmware {

template <GeneratedModel M>
class Boundary {
 public:
  using N = Numerics<M>;
  using Value = typename M::Value;

  // Converts with the standardisation of `tensors` (the compiled-in model by
  // default), which must outlive the boundary.
  explicit constexpr Boundary(const ModelTensors<M>& tensors = kCompiledTensors<M>) noexcept : t_(&tensors) {}

  // x_t from y_t and y_{t-1} (physical): channel i is y[kXSource[i]], or its
  // change since t-1 if kXIsDelta[i]; standardised, Q(kFracIn).
  void x_from_frames(const float (&y_t)[M::kY], const float (&y_prev)[M::kY],
                            Value (&x)[M::kX]) const noexcept {
    for (int i = 0; i < M::kX; ++i) {
      const int s = M::kXSource[i];
      const float raw = M::kXIsDelta[i] ? y_t[s] - y_prev[s] : y_t[s];
      x[i] = N::template from_real<M::kFracIn>((raw - t_->x_mean[i]) * t_->x_inv_std[i]);
    }
  }
  // Physical y -> standardised, Q(kFracY).
  void y_to_model(const float (&y)[M::kY], Value (&out)[M::kY]) const noexcept {
    for (int i = 0; i < M::kY; ++i) {
      out[i] = N::template from_real<M::kFracY>((y[i] - t_->y_mean[i]) * t_->y_inv_std[i]);
    }
  }
  // Standardised Q(kFracY) -> physical y.
  void y_to_physical(const Value (&v)[M::kY], float (&out)[M::kY]) const noexcept {
    for (int i = 0; i < M::kY; ++i) {
      out[i] = N::template to_real<M::kFracY>(v[i]) * t_->y_std[i] + t_->y_mean[i];
    }
  }
  // Physical command -> standardised, Q(kFracIn).
  void u_to_model(const float (&u)[M::kU], Value (&out)[M::kU]) const noexcept {
    for (int i = 0; i < M::kU; ++i) out[i] = u_to_model(i, u[i]);
  }
  // Command slot i alone: physical -> standardised, Q(kFracIn).
  Value u_to_model(int i, float u) const noexcept {
    return N::template from_real<M::kFracIn>((u - t_->u_mean[i]) * t_->u_inv_std[i]);
  }
  // Standardised Q(kFracIn) -> physical command.
  void u_to_physical(const Value (&v)[M::kU], float (&out)[M::kU]) const noexcept {
    for (int i = 0; i < M::kU; ++i) {
      out[i] = N::template to_real<M::kFracIn>(v[i]) * t_->u_std[i] + t_->u_mean[i];
    }
  }
  // A standardised real vector (e.g. a PB from the link) -> Q(kFracIn).
  template <int Size>
  static void real_to_in(const float (&v)[Size], Value (&out)[Size]) noexcept {
    for (int i = 0; i < Size; ++i) out[i] = N::template from_real<M::kFracIn>(v[i]);
  }

 private:
  const ModelTensors<M>* t_;
};

}  // namespace hadynet::firmware

#endif  // HADYNET_FIRMWARE_CORE_BOUNDARY_H_
