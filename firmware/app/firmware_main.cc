// The firmware: the q15 runtime behind the UART and (on a board with one)
// the USB device, and its own 5 Hz loop. Portable: the board
// (boards/board.h) is whichever one the build links, and so is the USB side
// (usb_link.h: usb_link.cc or usb_link_none.cc).
//
//   loop:
//     every received byte -> UartEndpoint::receive() -> reply bytes -> UART
//     (uart_endpoint.h: THE place where the link plugs in)
//     usb_service(): controller events; CDC-ACM bytes -> a second link port
//       on the same dispatcher (same runtime and loop) -> bulk IN; DFU work
//     every 0.2 s (SysTick) -> the period (period_loop.h): the board's
//       loadcells + the newest muscle state from the link -> one runtime
//       step -> the period record (period_record.h), which the link sends
//       on request (0x08) and usb_publish() sends as HID telemetry.
//
// At start-up the model is chosen (docs/model-update.md): on a board with
// model flash, the boot rule of firmware/model_update/model_slots.h picks
// a signed model image from the two slots (a new one passes its self-test
// first) or the compiled-in model, and the runtime reads the chosen one in
// place.
//
// All state is static (no heap); the runtime is constructed before main()
// by the start-up code's static constructors.
#include <cstdint>
#include <optional>
#include <span>
#include <type_traits>

#include "boards/board.h"
#include "firmware/app/channel_layout.h"
#include "firmware/app/image_checks.h"
#include "firmware/app/model_store.h"
#include "firmware/app/period_loop.h"
#include "firmware/app/uart_endpoint.h"
#include "firmware/app/usb_link.h"
#include "firmware/core/hadynet_runtime.h"
#include "hadynet_model_q15.h"

namespace {

using Model = hadynet::model_q15::Model;
using Loop = hadynet::app::PeriodLoop<Model>;

static_assert(std::is_same_v<Model, hadynet::app::FirmwareModel>, "usb_link.h serves the firmware's model");
// Board reading k is the model's loadcell k, and the model steps at the board's period.
static_assert(hadynet::app::model_fits_board<Model>());

hadynet::firmware::HadynetRuntime<Model> g_runtime;
hadynet::app::UartEndpoint<Model> g_endpoint(g_runtime);
std::optional<hadynet::model_update::ModelSlots> g_model_slots;  // on a board with model flash

// Chooses the model (the boot rule). On a board without model flash the
// compiled-in model runs.
void boot_model() noexcept {
  if (const hadynet::board::ModelFlash* flash = hadynet::board::model_flash()) {
    g_model_slots.emplace(flash->device, flash->slot_a, flash->slot_b, hadynet::app::model_identity<Model>(),
                          hadynet::board::config::kModelPublicKey, flash->mapped);
    hadynet::app::boot_model(*g_model_slots, g_runtime);
  }
}

// The 5 Hz job: one period of the autonomous loop, its work timed against
// the period (overruns are counted in the records).
void periodic() noexcept {
  const std::uint32_t start = hadynet::board::ticks();
  Loop::LoadcellReading reading;
  reading.valid = hadynet::board::read_loadcells(reading.newtons);
  Loop& loop = g_endpoint.loop();
  loop.run_period(reading, hadynet::board::overrun_periods());
  const std::uint32_t ticks_per_period = hadynet::board::description().tick_hz / hadynet::board::kPeriodHz;
  loop.end_period(hadynet::board::ticks() - start, ticks_per_period);
  hadynet::app::usb_publish(loop.latest());
}

}  // namespace

int main() {
  hadynet::board::init();
  boot_model();
  hadynet::app::usb_start(g_endpoint.dispatcher(), g_model_slots ? &*g_model_slots : nullptr);
  for (;;) {
    std::uint8_t byte;
    while (hadynet::board::uart_read_byte(byte)) {
      const std::span<const std::uint8_t> reply = g_endpoint.receive(byte);
      if (!reply.empty()) hadynet::board::uart_write(reply.data(), reply.size());
    }
    hadynet::app::usb_service();
    if (hadynet::board::period_elapsed()) periodic();
  }
}
