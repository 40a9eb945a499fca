// mps2-an386 (Cortex-M4F, CMSDK peripherals; QEMU -M mps2-an386): UART0 at
// 115200 baud with an interrupt-driven receive buffer, SysTick on the 25 MHz
// SYSCLK. No ADC: synthetic loadcell readings (synthetic_loadcells.h).
// Memory sizes and the clock: board.cmake.
#include <cstddef>
#include <cstdint>

#include "board_config.h"
#include "boards/board.h"
#include "boards/common/cortex_m.h"
#include "boards/common/irq_vectors.h"
#include "boards/common/rx_ring.h"
#include "boards/mps2-an386/synthetic_loadcells.h"

namespace hadynet::board {
namespace {

namespace cm = cortex_m;

// CMSDK APB UART0 (Cortex-M System Design Kit UART).
constexpr std::uintptr_t kUart0 = 0x40004000;
constexpr std::uintptr_t kUartData = kUart0 + 0x000;      // received / to-transmit byte
constexpr std::uintptr_t kUartState = kUart0 + 0x004;     // bit 0 TX full, bit 1 RX full, 2/3 overruns
constexpr std::uintptr_t kUartCtrl = kUart0 + 0x008;      // enables
constexpr std::uintptr_t kUartIntClear = kUart0 + 0x00C;  // write 1 to clear an interrupt
constexpr std::uintptr_t kUartBaudDiv = kUart0 + 0x010;   // SYSCLK / baud, >= 16
constexpr std::uint32_t kStateTxFull = 1u << 0;
constexpr std::uint32_t kStateRxFull = 1u << 1;
constexpr std::uint32_t kStateOverruns = (1u << 2) | (1u << 3);  // write 1 to clear
constexpr std::uint32_t kCtrlTxEnable = 1u << 0;
constexpr std::uint32_t kCtrlRxEnable = 1u << 1;
constexpr std::uint32_t kCtrlRxInterrupt = 1u << 3;
constexpr std::uint32_t kIntRx = 1u << 1;
constexpr int kUart0RxIrq = 0;  // NVIC line of UART0's receive interrupt

constexpr std::uint32_t kBaud = 115200;
constexpr std::uint32_t kBaudDiv = (config::kCoreClockHz + kBaud / 2) / kBaud;
static_assert(kBaudDiv >= 16, "CMSDK UART needs BAUDDIV >= 16");

// Room for two maximal wire frames (2 x 513 bytes, next power of two): a
// whole frame arriving while the main loop is busy (a control period, or
// QEMU delivering a burst faster than any baud rate) is never dropped.
RxRing<2048> g_rx;

std::uint32_t g_loadcell_scans = 0;  // read_loadcells() calls so far: the synthetic scan index

constexpr Description kDescription = {
    config::kName, config::kCoreClockHz, config::kCoreClockHz, config::kFlashBytes, config::kRamBytes,
};

}  // namespace

const Description& description() noexcept { return kDescription; }

void init() noexcept {
  cm::reg(kUartBaudDiv) = kBaudDiv;
  cm::reg(kUartState) = kStateOverruns;
  cm::reg(kUartCtrl) = kCtrlTxEnable | kCtrlRxEnable | kCtrlRxInterrupt;
  cm::nvic_enable(kUart0RxIrq);
  cm::start_systick(config::kCoreClockHz);
}

bool uart_read_byte(std::uint8_t& byte) noexcept { return g_rx.pop(byte); }

void uart_write(const std::uint8_t* data, std::size_t size) noexcept {
  for (std::size_t i = 0; i < size; ++i) {
    while ((cm::reg(kUartState) & kStateTxFull) != 0) {
    }
    cm::reg(kUartData) = data[i];
  }
}

// Scan n = the n-th call (synthetic_loadcells.h); always available.
bool read_loadcells(std::span<float> newtons) noexcept {
  if (newtons.size() != static_cast<std::size_t>(config::kLoadcells)) return false;
  float scan[config::kLoadcells];
  mps2::synthetic_loadcells(g_loadcell_scans, scan);
  ++g_loadcell_scans;
  for (int k = 0; k < config::kLoadcells; ++k) newtons[static_cast<std::size_t>(k)] = scan[k];
  return true;
}

}  // namespace hadynet::board

extern "C" void Uart0Rx_Handler() {
  namespace cm = hadynet::board::cortex_m;
  using namespace hadynet::board;
  cm::reg(kUartIntClear) = kIntRx;
  while ((cm::reg(kUartState) & kStateRxFull) != 0) {
    g_rx.push(static_cast<std::uint8_t>(cm::reg(kUartData)));
  }
}

namespace hadynet::board {
namespace {

__attribute__((section(".isr_vector.irq"), used)) constexpr auto g_irq_vectors =
    make_irq_vectors<config::kIrqCount>({{kUart0RxIrq, Uart0Rx_Handler}});

}  // namespace
const ModelFlash* model_flash() noexcept { return nullptr; }

}  // namespace hadynet::board
