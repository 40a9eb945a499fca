// The benchmark image (not a test): SysTick cycles of the core's jobs,
// reported over the UART for bench/qemu_icount.sh. Under QEMU with
// `-icount shift=0` every instruction takes 1 ns of virtual time, so the
// 25 MHz SysTick of mps2-an386 advances once per 40 instructions and the
// cycle counts are instruction counts (to 40 instructions, plus the SysTick
// interrupt's own few instructions every 10 ms).
//
// Output, one line each (then the program exits with 0):
//   bench board=<name> numeric=<q15|f32> tick_hz=<Hz> model=<hash>
//   job name=<job> reps=<n> ticks=<SysTick cycles, all reps> macs=<MACs per rep>
//   checksum value=<16 hex digits>        (runtime_checksum.h)
//   memory stack_used=<bytes> stack=<bytes> runtime=<sizeof runtime>
//   end
// Jobs (MACs from firmware/core/mac_count.h):
//   step          one HADYNET step (LSTM + decoder), MacCount::step
//   detect        a detect-mode period: runtime.step (prediction, d), MacCount::detect
//   control_full  a control-mode period with every epoch and step size run
//                 (Settings::keep_if_no_descent = false, so no early stop):
//                 exactly MacCount::period_control
//   control       a control-mode period with the default settings (may stop
//                 early; same MAC denominator, so it reads as <= the above)
//   adapt         a detect-mode period with PB adaptation running its full
//                 budget (PbAdapter::Settings::windows_per_period windows),
//                 MacCount::period_adapt
#ifndef HADYNET_FIRMWARE_APP_BENCH_H_
#define HADYNET_FIRMWARE_APP_BENCH_H_

#include <cstdint>
#include <string_view>

#include "boards/board.h"
#include "firmware/app/runtime_checksum.h"
#include "firmware/app/synthetic_frames.h"
#include "firmware/app/text.h"
#include "firmware/core/hadynet_runtime.h"
#include "firmware/core/mac_count.h"

namespace hadynet::app {

template <firmware::GeneratedModel M>
class Bench {
 public:
  using Runtime = firmware::HadynetRuntime<M>;
  using Macs = firmware::MacCount<M>;
  using Value = typename M::Value;

  // `runtime` and `net` are freshly constructed (static storage: they are
  // too large for the stack).
  [[noreturn]] static void run(Runtime& runtime, firmware::HadynetNet<M>& net) noexcept {
    Text<160> line;
    line << "bench board=" << board::description().name << " numeric=" << firmware::numeric_name(M::kNumeric)
         << " tick_hz=" << board::description().tick_hz << " model=";
    line.hex(M::kModelHash) << '\n';
    emit(line);

    // The checksum first: it needs the runtime as constructed.
    const std::uint64_t checksum = runtime_checksum(runtime);

    bench_step(net);

    SyntheticFrames<M> frames(0xBE7C0001u);
    firmware::SensorFrame<M> frame;
    runtime.reset();
    runtime.set_mode(firmware::Mode::kDetect);
    for (int k = 0; k < M::kDetectSteps + 2; ++k) {  // fill the detector's history
      frames.next(frame);
      (void)runtime.step(frame);
    }
    constexpr int kReps = 3;
    std::uint32_t ticks = 0;
    for (int k = 0; k < kReps; ++k) ticks += timed_step(runtime, frames);
    report("detect", kReps, ticks, Macs::detect);

    runtime.control_settings().keep_if_no_descent = false;
    runtime.set_mode(firmware::Mode::kControl);
    (void)timed_step(runtime, frames);  // first control period: takes y_ref, plans from the hold sequence
    ticks = 0;
    for (int k = 0; k < kReps; ++k) ticks += timed_step(runtime, frames);
    report("control_full", kReps, ticks, Macs::period_control);

    runtime.control_settings() = typename firmware::GraspStabilizer<M>::Settings{};
    ticks = 0;
    for (int k = 0; k < kReps; ++k) ticks += timed_step(runtime, frames);
    report("control", kReps, ticks, Macs::period_control);

    // Adaptation: frames until the first epoch starts (no work before), then
    // periods that each run the full budget of windows.
    runtime.reset();
    runtime.set_mode(firmware::Mode::kDetect);
    runtime.set_adapting(true);
    const int start_frames = runtime.adapter().settings().start_windows + M::kTrainSteps + 1;
    for (int k = 0; k < start_frames; ++k) {
      frames.next(frame);
      (void)runtime.step(frame);
    }
    ticks = 0;
    for (int k = 0; k < kReps; ++k) ticks += timed_step(runtime, frames);
    report("adapt", kReps, ticks, Macs::period_adapt(runtime.adapter().settings().windows_per_period));
    runtime.set_adapting(false);

    line.clear();
    line << "checksum value=";
    line.hex(checksum) << '\n';
    emit(line);
    line.clear();
    line << "memory stack_used=" << board::stack_used_bytes() << " stack=" << board::stack_size_bytes()
         << " runtime=" << sizeof(Runtime) << '\n';
    emit(line);
    line.clear();
    line << "end\n";
    emit(line);
    board::exit(0);
  }

 private:
  template <std::size_t N>
  static void emit(const Text<N>& text) noexcept {
    board::uart_write(text.bytes().data(), text.bytes().size());
  }
  static void report(std::string_view job, int reps, std::uint32_t ticks, long macs) noexcept {
    Text<128> line;
    line << "job name=" << job << " reps=" << reps << " ticks=" << ticks << " macs=" << macs << '\n';
    emit(line);
  }

  static std::uint32_t timed_step(Runtime& runtime, SyntheticFrames<M>& frames) noexcept {
    firmware::SensorFrame<M> frame;
    frames.next(frame);
    const std::uint32_t t0 = board::ticks();
    const firmware::StepResult<M> r = runtime.step(frame);
    const std::uint32_t t1 = board::ticks();
    sink_ = sink_ + (r.contact ? 1u : 0u);
    return t1 - t0;
  }

  // One HADYNET step, averaged over kSteps from a state after a few steps.
  static void bench_step(firmware::HadynetNet<M>& net) noexcept {
    SyntheticFrames<M> frames(0x57E90001u);
    firmware::SensorFrame<M> f0, f1;
    frames.next(f0);
    frames.next(f1);
    Value x[M::kX];
    firmware::Boundary<M>{}.x_from_frames(f1.y, f0.y, x);
    Value pb[M::kPb] = {};
    net.encode(x, pb);
    Value u[M::kU];
    Value y[M::kY];
    firmware::Boundary<M>{}.u_to_model(f1.u_prev, u);
    for (int k = 0; k < 4; ++k) net.step(u, y);
    constexpr int kSteps = 32;
    const std::uint32_t t0 = board::ticks();
    for (int k = 0; k < kSteps; ++k) net.step(u, y);
    const std::uint32_t t1 = board::ticks();
    sink_ = sink_ + (y[0] != Value{} ? 1u : 0u);
    report("step", kSteps, t1 - t0, Macs::step);
  }

  // Keeps results alive so the timed work cannot be optimised away.
  static inline volatile std::uint32_t sink_ = 0;
};

}  // namespace hadynet::app

#endif  // HADYNET_FIRMWARE_APP_BENCH_H_
