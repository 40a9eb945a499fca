// A board's external-interrupt vectors (NVIC lines 0..N-1): every line halts
// in Default_Handler except the ones the board binds. The board defines
//   __attribute__((section(".isr_vector.irq"), used))
//   constexpr auto g_irq_vectors = make_irq_vectors<config::kIrqCount>({{line, handler}, ...});
// and the linker script places it right after the core vectors.
#ifndef HADYNET_BOARDS_COMMON_IRQ_VECTORS_H_
#define HADYNET_BOARDS_COMMON_IRQ_VECTORS_H_

#include <cstddef>

extern "C" [[noreturn]] void Default_Handler();  // boards/common/startup.cc

namespace hadynet::board {

using Handler = void (*)();

template <int N>
struct IrqVectors {
  Handler handlers[N];
};

struct IrqBinding {
  int line;
  Handler handler;
};

template <int N, std::size_t K>
constexpr IrqVectors<N> make_irq_vectors(const IrqBinding (&bindings)[K]) {
  IrqVectors<N> table{};
  for (Handler& h : table.handlers) h = Default_Handler;
  for (const IrqBinding& b : bindings) table.handlers[b.line] = b.handler;  // out of range: not a constant
  return table;
}

}  // namespace hadynet::board

#endif  // HADYNET_BOARDS_COMMON_IRQ_VECTORS_H_
