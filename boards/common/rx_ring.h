// Receive buffer between a UART's receive interrupt (the only writer) and the
// main loop (the only reader): a single-producer single-consumer ring of
// kSize bytes, lock-free on the Cortex-M4 (aligned 32-bit loads and stores of
// the indices are atomic; the barrier orders data before index). Bytes that
// arrive while it is full are dropped and counted.
#ifndef HADYNET_BOARDS_COMMON_RX_RING_H_
#define HADYNET_BOARDS_COMMON_RX_RING_H_

#include <cstdint>

namespace hadynet::board {

template <std::uint32_t kSize>
class RxRing {
  static_assert(kSize >= 2 && (kSize & (kSize - 1)) == 0, "size must be a power of two");

 public:
  // Interrupt side.
  void push(std::uint8_t byte) noexcept {
    const std::uint32_t head = head_;
    if (head - tail_ == kSize) {
      dropped_ = dropped_ + 1;
      return;
    }
    data_[head % kSize] = byte;
    asm volatile("dmb" ::: "memory");
    head_ = head + 1;
  }
  // Main-loop side.
  bool pop(std::uint8_t& byte) noexcept {
    const std::uint32_t tail = tail_;
    if (head_ == tail) return false;
    asm volatile("dmb" ::: "memory");
    byte = data_[tail % kSize];
    tail_ = tail + 1;
    return true;
  }
  std::uint32_t dropped() const noexcept { return dropped_; }

 private:
  volatile std::uint32_t head_ = 0;  // bytes pushed (wraps)
  volatile std::uint32_t tail_ = 0;  // bytes popped (wraps)
  volatile std::uint32_t dropped_ = 0;
  volatile std::uint8_t data_[kSize] = {};
};

}  // namespace hadynet::board

#endif  // HADYNET_BOARDS_COMMON_RX_RING_H_
