// stm32f405: clock tree to 168 MHz (clock_tree.cc), USART1 on PA9 (TX) /
// PA10 (RX) at 115200 baud with an interrupt-driven receive buffer, SysTick
// on the core clock, the nine loadcells by ADC1 + DMA2 (loadcells.cc).
// QEMU's netduinoplus2 connects its first serial port (-serial) to USART1.
// Memory sizes and the clock: board.cmake.
#include <cstddef>
#include <cstdint>

#include "board_config.h"
#include "boards/board.h"
#include "boards/common/cortex_m.h"
#include "boards/common/irq_vectors.h"
#include "boards/common/rx_ring.h"
#include "boards/stm32f405/clock_tree.h"
#include "boards/stm32f405/loadcell_calibration.h"
#include "boards/stm32f405/loadcells.h"
#include "boards/stm32f405/stm32f405_registers.h"

namespace hadynet::board {
namespace {

namespace cm = cortex_m;
using cm::reg;

constexpr std::uint32_t kBaud = 115200;
constexpr int kTxPin = 9, kRxPin = 10;  // PA9, PA10
constexpr std::uint32_t kUsart1AlternateFunction = 7;

// Room for two maximal wire frames (2 x 513 bytes, next power of two): a
// whole frame arriving while the main loop is busy (a control period, or
// QEMU delivering a burst faster than any baud rate) is never dropped.
RxRing<2048> g_rx;

// Filled in by init() with the clock the board actually runs at.
Description g_description = {
    config::kName, config::kCoreClockHz, config::kCoreClockHz, config::kFlashBytes, config::kRamBytes,
};

void init_usart1(std::uint32_t apb2_hz) noexcept {
  using namespace stm32;
  reg(kRccAhb1Enr) |= kRccAhb1EnrGpioA;
  reg(kRccApb2Enr) |= kRccApb2EnrUsart1;
  cortex_m::read_back(kRccApb2Enr);
  const std::uintptr_t moder = kGpioA + kGpioModer;
  reg(moder) = (reg(moder) & ~((3u << (2 * kTxPin)) | (3u << (2 * kRxPin)))) |
               (kGpioModeAlternate << (2 * kTxPin)) | (kGpioModeAlternate << (2 * kRxPin));
  const std::uintptr_t afrh = kGpioA + kGpioAfrh;
  reg(afrh) = (reg(afrh) & ~((0xFu << (4 * (kTxPin - 8))) | (0xFu << (4 * (kRxPin - 8))))) |
              (kUsart1AlternateFunction << (4 * (kTxPin - 8))) | (kUsart1AlternateFunction << (4 * (kRxPin - 8)));
  reg(kUsartBrr) = (apb2_hz + kBaud / 2) / kBaud;  // oversampling by 16: mantissa.fraction = f / baud
  reg(kUsartCr1) = kUsartCr1Enable | kUsartCr1TxEnable | kUsartCr1RxEnable | kUsartCr1RxInterrupt;
  cm::nvic_enable(kUsart1Irq);
}

}  // namespace

const Description& description() noexcept { return g_description; }

void init() noexcept {
  const stm32::Clocks clocks = stm32::configure_clocks();
  g_description.core_clock_hz = clocks.core_hz;
  g_description.tick_hz = clocks.core_hz;
  init_usart1(clocks.apb2_hz);
  stm32::start_loadcell_scan();
  cm::start_systick(clocks.core_hz);
}

bool uart_read_byte(std::uint8_t& byte) noexcept { return g_rx.pop(byte); }

void uart_write(const std::uint8_t* data, std::size_t size) noexcept {
  for (std::size_t i = 0; i < size; ++i) {
    while ((reg(stm32::kUsartSr) & stm32::kUsartSrTxEmpty) == 0) {
    }
    reg(stm32::kUsartDr) = data[i];
  }
}

bool read_loadcells(std::span<float> newtons) noexcept {
  if (newtons.size() != static_cast<std::size_t>(config::kLoadcells)) return false;
  std::uint16_t counts[config::kLoadcells];
  if (!stm32::loadcell_counts(counts)) return false;
  for (int i = 0; i < config::kLoadcells; ++i) {
    const float volts = static_cast<float>(counts[i]) * stm32::kAdcVoltsPerCount;
    newtons[static_cast<std::size_t>(i)] = (volts - stm32::kLoadcellZeroVolts[i]) * stm32::kLoadcellNewtonsPerVolt[i];
  }
  return true;
}

}  // namespace hadynet::board

extern "C" void Usart1_Handler() {
  using namespace hadynet::board;
  // Reading SR then DR clears RXNE and an overrun.
  while ((cortex_m::reg(stm32::kUsartSr) & (stm32::kUsartSrRxNotEmpty | stm32::kUsartSrOverrun)) != 0) {
    g_rx.push(static_cast<std::uint8_t>(cortex_m::reg(stm32::kUsartDr)));
  }
}

namespace hadynet::board {
namespace {

__attribute__((section(".isr_vector.irq"), used)) constexpr auto g_irq_vectors =
    make_irq_vectors<config::kIrqCount>({{stm32::kUsart1Irq, Usart1_Handler}});

}  // namespace
}  // namespace hadynet::board
