// The firmware: the q15 runtime behind the UART, and the 5 Hz loop.
// Portable: the board (boards/board.h) is whichever one the build links.
//
//   loop:
//     every received byte -> UartEndpoint::receive() -> reply bytes -> UART
//     (uart_endpoint.h: THE place where the link plugs in)
//     every 0.2 s (SysTick)  -> the periodic job: read the loadcells
//
// All state is static (no heap); the runtime is constructed before main()
// by the start-up code's static constructors.
#include <cstdint>
#include <span>

#include "boards/board.h"
#include "firmware/app/loadcell_snapshot.h"
#include "firmware/app/uart_endpoint.h"
#include "firmware/core/hadynet_runtime.h"
#include "hadynet_model_q15.h"

namespace {

using Model = hadynet::model_q15::Model;

hadynet::firmware::HadynetRuntime<Model> g_runtime;
hadynet::app::LoadcellSnapshot g_loadcells;
hadynet::app::UartEndpoint<Model> g_endpoint(g_runtime);
std::uint32_t g_period = 0;

// The 5 Hz job. The runtime's step is driven by sensor frames from the link
// (the host owns the robot's sensors today); what the board measures itself
// is sampled here (protocol version 1 does not carry it yet).
void periodic() noexcept {
  ++g_period;
  float newtons[hadynet::board::kLoadcells];
  if (hadynet::board::read_loadcells(newtons)) {
    for (int i = 0; i < hadynet::board::kLoadcells; ++i) g_loadcells.newtons[i] = newtons[i];
    g_loadcells.period = g_period;
    g_loadcells.valid = true;
  }
}

}  // namespace

int main() {
  hadynet::board::init();
  for (;;) {
    std::uint8_t byte;
    while (hadynet::board::uart_read_byte(byte)) {
      const std::span<const std::uint8_t> reply = g_endpoint.receive(byte);
      if (!reply.empty()) hadynet::board::uart_write(reply.data(), reply.size());
    }
    if (hadynet::board::period_elapsed()) periodic();
  }
}
